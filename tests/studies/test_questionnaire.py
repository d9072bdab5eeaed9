"""questionnaire.json as a person and the report read it: the answers by method, one line
each, beside the questions and what their ends meant as the participant saw them; a file of
the older form (answers only) still read, and resumed in its own form; a file recording other
wording not added to; a damaged file named."""

import json

import pytest

from pbp_drake.studies.questionnaire import (
    QuestionnaireError, read_answers, read_questionnaire, save_answer, scales_text)

AS_ASKED = {
    "tiredness": {"question": "How tired did you feel?", "0": "very tired",
                  "5": "not tired at all"},
    "ease": {"question": "How easy was it to operate the robot?", "0": "very hard",
             "5": "very easy"}}


def test_the_file_keeps_the_answers_by_method_beside_the_questions_as_asked(tmp_path):
    for method, tiredness, ease in (("teleop", 1, 0), ("pbp_alternated", 4, 3)):
        save_answer(tmp_path, method, "tiredness", tiredness)
        save_answer(tmp_path, method, "ease", ease)
    text = (tmp_path / "questionnaire.json").read_text()
    # A method's answers on one line, in the order the session gave them.
    assert '  "teleop": {"tiredness": 1, "ease": 0},\n' in text
    assert '  "pbp_alternated": {"tiredness": 4, "ease": 3}\n' in text
    assert text.index('"teleop"') < text.index('"pbp_alternated"')
    assert json.loads(text) == {"answers": {"teleop": {"tiredness": 1, "ease": 0},
                                            "pbp_alternated": {"tiredness": 4, "ease": 3}},
                                "questions": AS_ASKED}
    assert read_questionnaire(tmp_path) == (json.loads(text)["answers"], AS_ASKED)
    assert not list(tmp_path.glob(".*.tmp"))  # written atomically, nothing left beside it


def test_an_older_file_without_the_questions_is_read_and_resumed_in_its_form(tmp_path):
    path = tmp_path / "questionnaire.json"
    path.write_text(json.dumps({"teleop": {"ease": 4, "tiredness": 1}}))
    assert read_questionnaire(tmp_path) == ({"teleop": {"ease": 4, "tiredness": 1}}, None)
    save_answer(tmp_path, "pbp_alternated", "tiredness", 3)
    # Still answers only: it claims no labels its first answers may not have been given under.
    assert json.loads(path.read_text()) == {"teleop": {"ease": 4, "tiredness": 1},
                                            "pbp_alternated": {"tiredness": 3}}
    with pytest.raises(QuestionnaireError, match="teleop ease is already answered"):
        save_answer(tmp_path, "teleop", "ease", 0)


def test_a_file_recording_other_wording_is_read_but_not_added_to(tmp_path):
    path = tmp_path / "questionnaire.json"
    other = {**AS_ASKED, "ease": {**AS_ASKED["ease"], "0": "bad", "5": "good"}}
    path.write_text(json.dumps({"answers": {"teleop": {"ease": 2}}, "questions": other}))
    before = path.read_bytes()
    assert read_answers(tmp_path) == {"teleop": {"ease": 2}}
    with pytest.raises(QuestionnaireError, match="records its questions worded otherwise"):
        save_answer(tmp_path, "teleop", "tiredness", 3)
    assert path.read_bytes() == before


@pytest.mark.parametrize("held, problem", [
    ([1, 2], "holds a list"),
    ({"answers": {}}, 'holds [\'answers\']; expected exactly "answers" and "questions"'),
    ({"answers": [], "questions": AS_ASKED}, '"answers" holds a list'),
    ({"answers": {}, "questions": {"ease": "very easy"}}, '"questions" is not {question:'),
    ({"answers": {}, "questions": {"mood": {"0": "sad"}}}, "unknown question 'mood'"),
    ({"answers": {"teleop": {"ease": 6}}, "questions": AS_ASKED},
     "teleop ease: the answer 6 is outside 0 to 5 (0 = very hard to 5 = very easy)"),
    ({"teleop": {"tiredness": True}},
     "teleop tiredness: the answer True is outside 0 to 5 (0 = very tired to 5 = not tired"),
    ({"teleop": 3}, "the answers of 'teleop' are not a mapping"),
])
def test_a_damaged_file_is_named_with_its_problem(tmp_path, held, problem):
    path = tmp_path / "questionnaire.json"
    path.write_text(json.dumps(held))
    with pytest.raises(QuestionnaireError) as error:
        read_answers(tmp_path)
    assert str(error.value).startswith(f"{path}: ") and problem in str(error.value)


def test_a_truncated_file_is_named(tmp_path):
    path = tmp_path / "questionnaire.json"
    path.write_text('{"answers": {"teleop": ')
    with pytest.raises(QuestionnaireError, match="unreadable or invalid JSON") as error:
        read_answers(tmp_path)
    assert str(error.value).startswith(f"{path}: ")


def test_the_scales_in_words_for_help_and_messages():
    assert scales_text() == ("0 to 5, higher is better (tiredness: 0 = very tired to 5 = not "
                             "tired at all; ease: 0 = very hard to 5 = very easy)")
