"""The paper's questionnaire (section V-C, Fig. 8): two questions answered 0 (bad) to 5 (good)
after each method of a session, kept in the participant folder's `questionnaire.json` as
`{method: {"tiredness": int, "ease": int}}`.

Each answer is written at once (atomically), so an interrupted session loses none and a
resumed one does not ask it again; an answer on disk is never overwritten.
"""

import json
import pathlib

from pbp_drake.scenarios import ScenarioError
from pbp_drake.studies.trial_files import write_atomically

# The keys of questionnaire.json and the questions as the paper asked them.
QUESTIONS = {"tiredness": "How tired did you feel?",
             "ease": "How easy was it to operate the robot?"}
SCALE = range(0, 6)  # 0 (bad) .. 5 (good)
QUESTIONNAIRE_FILE = "questionnaire.json"


class QuestionnaireError(ScenarioError):
    """A questionnaire answer or file that cannot be taken (exit 2, as any user error)."""


def check_answer(value, where):
    """`value` as an int of SCALE; raises QuestionnaireError naming `where` otherwise."""
    if isinstance(value, bool) or not isinstance(value, int) or value not in SCALE:
        raise QuestionnaireError(f"{where}: the answer {value!r} is outside 0 (bad) to 5 "
                                 "(good); answers are whole numbers 0, 1, 2, 3, 4 or 5")
    return value


def read_answers(folder):
    """The answers saved in `folder`'s questionnaire.json (`{}` when there is none). Raises
    QuestionnaireError, naming the file, when it is damaged or holds an answer outside 0-5
    or an unknown question."""
    path = pathlib.Path(folder) / QUESTIONNAIRE_FILE
    try:
        answers = json.loads(path.read_text())
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as error:
        raise QuestionnaireError(f"{path}: unreadable or invalid JSON ({error})") from None
    if not isinstance(answers, dict):
        raise QuestionnaireError(f"{path}: holds a {type(answers).__name__}, not "
                                 "{method: {question: answer}}")
    for method, entry in answers.items():
        if not isinstance(entry, dict):
            raise QuestionnaireError(f"{path}: the answers of {method!r} are not a mapping")
        for question, value in entry.items():
            if question not in QUESTIONS:
                raise QuestionnaireError(f"{path}: {method!r} answers an unknown question "
                                         f"{question!r} (the questions: {list(QUESTIONS)})")
            check_answer(value, f"{path}: {method} {question}")
    return answers


def save_answer(folder, method, question, value):
    """Adds one answer to `folder`'s questionnaire.json, atomically. Raises
    QuestionnaireError when the value is outside 0-5, or when that question of that method
    is already answered (a saved answer is never overwritten)."""
    check_answer(value, f"{method} {question}")
    if question not in QUESTIONS:
        raise QuestionnaireError(f"unknown question {question!r}; the questions: "
                                 f"{list(QUESTIONS)}")
    answers = read_answers(folder)
    entry = answers.setdefault(method, {})
    if question in entry:
        raise QuestionnaireError(f"{pathlib.Path(folder) / QUESTIONNAIRE_FILE}: {method} "
                                 f"{question} is already answered ({entry[question]}); a saved "
                                 "answer is not overwritten")
    entry[question] = value
    write_atomically(pathlib.Path(folder) / QUESTIONNAIRE_FILE,
                     json.dumps(answers, indent=1, sort_keys=True) + "\n")


def parse_answers(text, methods):
    """`--answers` for unattended sessions: comma-separated `[METHOD:]QUESTION=VALUE`, e.g.
    `tiredness=3,ease=4,teleop:tiredness=1` (an item without a method holds for every
    method; one with a method overrides it). Returns `{method: {question: value}}` with
    every question of every method in `methods` answered. Raises QuestionnaireError."""
    common, specific = {}, {}
    for item in (part.strip() for part in text.split(",")):
        key, equals, raw = item.partition("=")
        method, colon, question = key.strip().rpartition(":")
        if not equals or not question:
            raise QuestionnaireError(f"--answers: {item!r} is not [METHOD:]QUESTION=VALUE, "
                                     "e.g. tiredness=3,ease=4")
        if question not in QUESTIONS:
            raise QuestionnaireError(f"--answers: unknown question {question!r}; the "
                                     f"questions: {', '.join(QUESTIONS)}")
        if colon and method not in methods:
            raise QuestionnaireError(f"--answers: {method!r} is not one of the "
                                     f"participant's methods ({', '.join(methods)})")
        try:
            value = int(raw.strip())
        except ValueError:
            raise QuestionnaireError(f"--answers: {item!r}: {raw.strip()!r} is not a whole "
                                     "number 0 (bad) to 5 (good)") from None
        check_answer(value, f"--answers {item}")
        (specific.setdefault(method, {}) if colon else common)[question] = value
    answers = {}
    for method in methods:
        answers[method] = {**common, **specific.get(method, {})}
        missing = [q for q in QUESTIONS if q not in answers[method]]
        if missing:
            raise QuestionnaireError(f"--answers gives no {', '.join(missing)} for {method}: "
                                     "answer every question, e.g. tiredness=3,ease=4")
    return answers
