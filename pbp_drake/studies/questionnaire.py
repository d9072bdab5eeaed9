"""The paper's questionnaire (section V-C, Fig. 8): two questions answered 0 to 5 after each
method of a session, higher being better, each end labelled in words (`QUESTIONS`, the one
table of them). `questionnaire.json` keeps the answers by method beside the questions as
asked (docs/user-study.md, "Files and resuming"); a bare `{method: {question: answer}}`
file is read and kept in that form: it cannot vouch for the labels of its answers.
"""

import json
import pathlib
import typing

from pbp_drake.scenarios import ScenarioError
from pbp_drake.studies.atomic_files import read_text, write_atomically


class Question(typing.NamedTuple):
    """A question as the participant reads it, with what the two ends of its scale mean."""

    text: str
    lowest: str  # what 0 means
    highest: str  # what 5 means


# The keys of questionnaire.json and the questions as the paper asked them.
QUESTIONS = {"tiredness": Question("How tired did you feel?", "very tired", "not tired at all"),
             "ease": Question("How easy was it to operate the robot?", "very hard", "very easy")}
SCALE = range(0, 6)  # 0 (the worse end) .. 5 (the better end) of every question
QUESTIONNAIRE_FILE = "questionnaire.json"


class QuestionnaireError(ScenarioError):
    """A questionnaire answer or file that cannot be taken (exit 2, as any user error)."""


def end_label(question, value):
    """What `value` means for `question` at an end of the scale ("very tired" for
    tiredness 0), else None."""
    asked = QUESTIONS[question]
    return {SCALE[0]: asked.lowest, SCALE[-1]: asked.highest}.get(value)


def scale_text(question):
    """`question`'s scale in words: "0 = very tired to 5 = not tired at all"."""
    return (f"{SCALE[0]} = {end_label(question, SCALE[0])} to "
            f"{SCALE[-1]} = {end_label(question, SCALE[-1])}")


def scales_text():
    """Every question's scale, for help and messages that speak of them all: "0 to 5, higher
    is better (tiredness: 0 = very tired to 5 = not tired at all; ease: ...)"."""
    return (f"{SCALE[0]} to {SCALE[-1]}, higher is better ("
            + "; ".join(f"{key}: {scale_text(key)}" for key in QUESTIONS) + ")")


def recorded_questions():
    """The questions as questionnaire.json records them: per key, its text and end labels."""
    return {key: {"question": asked.text, str(SCALE[0]): asked.lowest,
                  str(SCALE[-1]): asked.highest} for key, asked in QUESTIONS.items()}


def check_answer(value, question, where):
    """`value` as an int of SCALE; QuestionnaireError naming `where` otherwise."""
    if isinstance(value, bool) or not isinstance(value, int) or value not in SCALE:
        raise QuestionnaireError(f"{where}: the answer {value!r} is outside {SCALE[0]} to "
                                 f"{SCALE[-1]} ({scale_text(question)}); answers are whole "
                                 "numbers 0, 1, 2, 3, 4 or 5")
    return value


def _check_question(question, where):
    if question not in QUESTIONS:
        raise QuestionnaireError(f"{where}: unknown question {question!r}; the questions: "
                                 f"{', '.join(QUESTIONS)}")


def read_questionnaire(folder):
    """`(answers, questions)` of `folder`'s questionnaire.json: the answers by method
    (`{}` without a file) and the recorded questions (None for a bare file). Raises
    QuestionnaireError when it is damaged or holds a bad answer or an unknown question."""
    path = pathlib.Path(folder) / QUESTIONNAIRE_FILE
    try:
        held = json.loads(read_text(path))
    except FileNotFoundError:
        return {}, None
    except (OSError, ValueError) as error:
        raise QuestionnaireError(f"{path}: unreadable or invalid JSON ({error})") from None
    if not isinstance(held, dict):
        raise QuestionnaireError(f"{path}: holds a {type(held).__name__}, not "
                                 '{"answers": {method: {question: answer}}, "questions": ...}')
    answers, questions = held, None
    if "answers" in held or "questions" in held:  # the form that records the questions
        if set(held) != {"answers", "questions"}:
            raise QuestionnaireError(f"{path}: holds {sorted(held)}; expected exactly "
                                     '"answers" and "questions"')
        answers, questions = held["answers"], held["questions"]
        if not isinstance(answers, dict):
            raise QuestionnaireError(f'{path}: "answers" holds a {type(answers).__name__}, '
                                     "not {method: {question: answer}}")
        if not isinstance(questions, dict) or not all(
                isinstance(labels, dict) and all(isinstance(text, str) for text in
                                                 labels.values())
                for labels in questions.values()):
            raise QuestionnaireError(f'{path}: "questions" is not '
                                     '{question: {"question": text, "0": label, "5": label}}')
        for question in questions:
            _check_question(question, f'{path}: "questions"')
    for method, entry in answers.items():
        if not isinstance(entry, dict):
            raise QuestionnaireError(f"{path}: the answers of {method!r} are not a mapping")
        for question, value in entry.items():
            _check_question(question, f"{path}: {method}")
            check_answer(value, question, f"{path}: {method} {question}")
    return answers, questions


def unanswered(answers, method):
    """The questions `answers` (`{method: {question: answer}}`) lacks for `method`, in the
    questionnaire's order."""
    given = answers.get(method, {})
    return [question for question in QUESTIONS if question not in given]


def read_answers(folder):
    """The answers of `read_questionnaire`, `{method: {question: answer}}`."""
    return read_questionnaire(folder)[0]


def save_answer(folder, method, question, value):
    """Adds one answer to `folder`'s questionnaire.json. Raises QuestionnaireError when the
    value is outside 0-5, when that question of that method is already answered, or when
    the file records the questions worded otherwise than they are now asked."""
    _check_question(question, method)
    check_answer(value, question, f"{method} {question}")
    path = pathlib.Path(folder) / QUESTIONNAIRE_FILE
    answers, questions = read_questionnaire(folder)
    older_form = questions is None and bool(answers)
    if questions is not None and questions != recorded_questions():
        raise QuestionnaireError(
            f"{path} records its questions worded otherwise ({questions}) than they are now "
            f"asked ({recorded_questions()}): finish the session with the pbp-drake that "
            "began it, or start the participant in a new folder")
    entry = answers.setdefault(method, {})
    if question in entry:
        raise QuestionnaireError(f"{path}: {method} {question} is already answered "
                                 f"({entry[question]}); a saved answer is not overwritten")
    entry[question] = value
    write_atomically(path, (json.dumps(answers, indent=1, sort_keys=True) + "\n")
                     if older_form else _file_text(answers))


def _file_text(answers):
    # One line per method and per question, in the order they were asked.
    def lines(mapping):
        return ",\n".join(f"  {json.dumps(key)}: {json.dumps(value)}"
                          for key, value in mapping.items())

    in_order = {method: {q: entry[q] for q in QUESTIONS if q in entry}
                for method, entry in answers.items()}
    return (f'{{\n "answers": {{\n{lines(in_order)}\n }},\n'
            f' "questions": {{\n{lines(recorded_questions())}\n }}\n}}\n')


def parse_answers(text, methods):
    """`--answers` for unattended sessions: comma-separated `[METHOD:]QUESTION=VALUE`, e.g.
    `tiredness=3,ease=4,teleop:tiredness=1` (an item with a method overrides one without).
    Returns `{method: {question: value}}`, every question answered, or raises
    QuestionnaireError."""
    common, specific = {}, {}
    for item in (part.strip() for part in text.split(",")):
        key, equals, raw = item.partition("=")
        method, colon, question = key.strip().rpartition(":")
        if not equals or not question:
            raise QuestionnaireError(f"--answers: {item!r} is not [METHOD:]QUESTION=VALUE, "
                                     "e.g. tiredness=3,ease=4")
        _check_question(question, "--answers")
        if colon and method not in methods:
            raise QuestionnaireError(f"--answers: {method!r} is not one of the "
                                     f"participant's methods ({', '.join(methods)})")
        try:
            value = int(raw.strip())
        except ValueError:
            raise QuestionnaireError(f"--answers: {item!r}: {raw.strip()!r} is not a whole "
                                     f"number {SCALE[0]} to {SCALE[-1]} "
                                     f"({scale_text(question)})") from None
        check_answer(value, question, f"--answers {item}")
        given = specific.setdefault(method, {}) if colon else common
        if question in given:  # not the last one, in silence
            raise QuestionnaireError(f"--answers: {key.strip()} is answered twice")
        given[question] = value
    answers = {}
    for method in methods:
        answers[method] = {**common, **specific.get(method, {})}
        missing = unanswered(answers, method)
        if missing:
            raise QuestionnaireError(f"--answers gives no {', '.join(missing)} for {method}: "
                                     "answer every question, e.g. tiredness=3,ease=4")
    return answers
