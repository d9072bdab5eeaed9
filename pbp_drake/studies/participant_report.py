"""`pbp-drake report STUDY_DIR` for a user study (a folder per participant): per method the
recorded runs' metrics and the answers, pairwise Wilcoxon signed-rank tests with Bonferroni
correction (the paper's section V-C) in results.md, and Fig. 8 (docs/user-study.md, "The
report"). Practice runs are never read.
"""

import collections
import itertools
import pathlib
import statistics
import sys

from pbp_drake.scenarios import METHOD_NAMES, ScenarioError, counted
from pbp_drake.studies.questionnaire import QUESTIONS, read_answers, scale_text, unanswered
from pbp_drake.studies.questionnaire_figure import FIG8, answer_counts, plot_questionnaire
from pbp_drake.studies.sessions import DEFAULT_SESSION_METHODS, PRACTICE_FOLDER
from pbp_drake.studies.atomic_files import write_atomically
from pbp_drake.studies.folders import folder_kind
from pbp_drake.studies.trial_files import (
    METHOD_COMPARISON, content_differences, name_damaged, read_study)

# A user study's folder holds participants' sessions alone (`pbp-drake session`).
NOT_A_SESSION = ("report it on its own (`pbp-drake report FOLDER`), or move it out of {}, "
                 "whose sub-folders are read as a user study's participants")
ALPHA = 0.05  # the family-wise level; each measure's pairs are Bonferroni-corrected
# The measures tested, in the paper's order: (key, name in the tables, source).
MEASURES = (("intervention_ratio", "intervention ratio", "trial"),
            ("task_time", "task time (s)", "trial"),
            ("tiredness", "tiredness (0-5)", "answer"),
            ("ease", "ease (0-5)", "answer"))


def is_participant_collection(folder):
    """Whether `folder` is not itself a study folder (no study.json, no trials/)."""
    folder = pathlib.Path(folder)
    return not (folder / "study.json").exists() and not (folder / "trials").is_dir()


def participant_folders(study_dir):
    """`study_dir`'s sub-folders holding a study.json or trials/, by name."""
    return sorted(p for p in pathlib.Path(study_dir).iterdir() if p.is_dir()
                  and ((p / "study.json").is_file() or (p / "trials").is_dir()))


def practice_only_folders(study_dir):
    """`study_dir`'s sub-folders holding practice/ and no study.json or trials/ of their own
    (a session stopped during its practice), by name."""
    return sorted(p for p in pathlib.Path(study_dir).iterdir()
                  if p.is_dir() and (p / PRACTICE_FOLDER).is_dir()
                  and not (p / "study.json").is_file() and not (p / "trials").is_dir())


def read_participants(study_dir):
    """`(sessions, damaged, practised)`: per participant folder name, its study, its runs by
    method (None when not on disk or damaged) and its answers; every damaged file; and the
    names of the folders that hold practice runs alone. Raises ScenarioError when there are
    no participant folders, or one holds another scenario."""
    study_dir = pathlib.Path(study_dir)
    if not study_dir.is_dir():
        raise ScenarioError(f"{study_dir}: no such folder")
    folders = participant_folders(study_dir)
    practised = [folder.name for folder in practice_only_folders(study_dir)]
    if not folders and practised:
        raise ScenarioError(f"{study_dir}: {', '.join(practised)} "
                            f"{'holds' if len(practised) == 1 else 'hold'} practice runs alone "
                            f"({PRACTICE_FOLDER}/, never counted; a session stopped during its "
                            "practice), and there is no other participant folder: nothing to "
                            "report")
    if not folders:
        raise ScenarioError(f"{study_dir} has no study.json and no trial files of a "
                            "`pbp-drake study`, and no participant folders (ID/study.json, "
                            "written by `pbp-drake session SCENARIO --participant ID --output "
                            f"{study_dir}/ID`): nothing to report")
    sessions, damaged = {}, []
    for folder in folders:
        kind = folder_kind(folder)  # None: a damaged study.json, which read_study names
        if kind not in (None, METHOD_COMPARISON):
            raise ScenarioError(f"{folder} holds a study of kind {kind!r}, not a participant's "
                                f"session: {NOT_A_SESSION.format(study_dir)}")
        study, records, broken = read_study(folder)
        if study["trials"] != 1:
            raise ScenarioError(f"{folder} is a study of {study['trials']} trials a method, "
                                "not a participant's session (one trial a method): "
                                + NOT_A_SESSION.format(study_dir))
        foreign = [d for d in broken if "another scenario" in d.problem]
        if foreign:
            raise ScenarioError(f"{foreign[0].path} is {foreign[0].problem}: participant "
                                f"folder {folder} mixes scenarios; move it out of {study_dir}")
        damaged += broken
        runs = {method: records.get((method, 0)) for method in study["methods"]}
        answers = read_answers(folder)
        unreadable = {d.key[0] for d in broken if d.key is not None}
        sessions[folder.name] = {
            "study": study, "runs": runs, "answers": answers,
            "damaged_runs": [m for m in study["methods"] if m in unreadable],
            # What an unfinished session lacks (a damaged run is named as damaged).
            "not_run": [m for m in study["methods"]
                        if runs[m] is None and m not in unreadable],
            "not_answered": [m for m in study["methods"] if unanswered(answers, m)]}
    _check_one_folder_each(study_dir, sessions)
    hashes = collections.Counter(s["study"]["scenario_hash"] for s in sessions.values())
    digest = hashes.most_common(1)[0][0]
    reference = next(s["study"] for s in sessions.values() if s["study"]["scenario_hash"]
                     == digest)
    for name, session in sessions.items():
        study = session["study"]
        if study["scenario_hash"] != digest:
            differences = content_differences(reference.get("scenario_content"),
                                              study.get("scenario_content"),
                                              ("in the others", "in this one"))
            raise ScenarioError(
                f"{study_dir / name} is a session of another scenario ({study['scenario']!r}, "
                f"hash {study['scenario_hash']}) than the other participants "
                f"({reference['scenario']!r}, hash {digest}{differences}): move it out of "
                f"{study_dir}, or report it on its own")
    return sessions, damaged, practised


def _check_one_folder_each(study_dir, sessions):
    """Raises ScenarioError when two folders hold sessions of one participant: the same ID
    recorded in their study.json, or (without one) names differing only in case."""
    seen = {}
    for name, session in sessions.items():
        participant = session["study"].get("participant") or name
        other = seen.setdefault(str(participant).casefold(), name)
        if other != name:
            held = sessions[other]["study"].get("participant") or other
            raise ScenarioError(
                f"{study_dir / other} and {study_dir / name} hold sessions of one participant "
                f"({f'both {held}' if held == participant else f'{held} and {participant}'})"
                ", who would be counted twice: keep the one that "
                f"counts in {study_dir}, and move the other out")


# What the report says of a folder whose session stopped during its practice.
PRACTICE_ONLY = "stopped during practice: no method run or answered"


def incomplete_sessions(sessions, practised=()):
    """`{participant: "Teleop not run; Teleop not answered"}` of the sessions that lack a
    method's run or an answer (a damaged run is not counted as lacking), and of the folders
    `practised` (practice runs alone), by name."""
    found = {name: PRACTICE_ONLY for name in practised}
    for name, session in sessions.items():
        parts = [f"{', '.join(map(_label, session[key]))} not {word}"
                 for key, word in (("not_run", "run"), ("not_answered", "answered"))
                 if session[key]]
        if parts:
            found[name] = "; ".join(parts)
    return dict(sorted(found.items()))


def answers_without_run(sessions):
    """`{participant: "Teleop: its trial file is damaged"}` of the sessions with answers to
    a method whose run the report does not count (damaged, or not on disk): the answers are
    counted all the same, being what the participant said after the run."""
    found, methods = {}, method_order(sessions)  # answers to other methods are not counted
    for name, session in sessions.items():
        parts = [f"{_label(method)}: "
                 + ("its trial file is damaged" if method in session["damaged_runs"]
                    else "not run")
                 for method in methods
                 if session["answers"].get(method) and session["runs"].get(method) is None]
        if parts:
            found[name] = "; ".join(parts)
    return found


def method_order(sessions):
    """The methods of all sessions: the paper's three first, then others as first met."""
    found = list(dict.fromkeys(m for s in sessions.values() for m in s["study"]["methods"]))
    return ([m for m in DEFAULT_SESSION_METHODS if m in found]
            + [m for m in found if m not in DEFAULT_SESSION_METHODS])


def measure_values(sessions, methods, measure, source):
    """`{method: {participant: value}}` of one measure (runs without error, answers given)."""
    values = {method: {} for method in methods}
    for name, session in sessions.items():
        for method in methods:
            if source == "trial":
                record = session["runs"].get(method)
                value = (None if record is None or record["error"] is not None
                         else record.get(measure))
            else:
                value = session["answers"].get(method, {}).get(measure)
            if value is not None:
                values[method][name] = value
    return values


# Who counts in a pair's test, by the measure's source, as the notes say it.
PAIRED_BY = {"trial": "ran both", "answer": "answered both"}


def wilcoxon_rows(values, methods, source):
    """Each pair of methods' two-sided Wilcoxon signed-rank test (scipy.stats.wilcoxon,
    its defaults), paired by participant: dicts of pair, n, statistic, p. Where there is
    nothing to test p is None and `note` says why in plain words (`source`, "trial" or
    "answer", names who counted)."""
    # Deferred: scipy.stats takes about 0.7 s to import, which every command would pay.
    import scipy.stats

    who = PAIRED_BY[source]
    rows = []
    for first, second in itertools.combinations(methods, 2):
        paired = sorted(set(values[first]) & set(values[second]))
        x = [values[first][p] for p in paired]
        y = [values[second][p] for p in paired]
        row = {"pair": (first, second), "n": len(paired), "statistic": None, "p": None,
               "note": ""}
        if len(paired) < 2:
            row["note"] = (f"a test needs at least 2 participants who {who}; "
                           f"{len(paired) or 'none'} did")
        elif all(a == b for a, b in zip(x, y)):
            # SciPy would warn and give p = 1 (or refuse, for older versions): no test.
            row["note"] = (f"nothing to test: each of the {len(paired)} participants who "
                           f"{who} has the same value for both")
        elif sum(a != b for a, b in zip(x, y)) == 1:
            # SciPy's default drops the equal pairs, leaving one: a meaningless p = 1.
            row["note"] = ("a test needs at least 2 participants whose values for the two "
                           f"differ; 1 of the {len(paired)} who {who} does")
        else:
            try:
                result = scipy.stats.wilcoxon(x, y)
                row["statistic"], row["p"] = float(result.statistic), float(result.pvalue)
            except ValueError as error:  # none known with two or more differing pairs
                row["note"] = f"the test could not be made ({error})"
        if row["p"] is not None and row["p"] != row["p"]:  # NaN: a value is not a number
            row["statistic"] = row["p"] = None
            row["note"] = "the test gave no p-value (a value is not a number)"
        rows.append(row)
    return rows


def _label(method):
    return METHOD_NAMES.get(method, method)


def _summary(values, source):
    """A trial measure's mean ± std (`mean (n = 1)` of one value: no spread), an answer's
    median (mean), or "-"."""
    values = list(values)
    if not values:
        return "-"
    if source == "answer":
        return f"{statistics.median(values):g} ({statistics.fmean(values):.2f})"
    if len(values) == 1:
        return f"{values[0]:.3f} (n = 1)"
    return f"{statistics.fmean(values):.3f} ± {statistics.pstdev(values):.3f}"


def participant_results(study_dir):
    """`(Markdown text, sessions, methods, damaged, incomplete)` of the report (incomplete:
    `incomplete_sessions`)."""
    sessions, damaged, practised = read_participants(study_dir)
    methods = method_order(sessions)
    values = {key: measure_values(sessions, methods, key, source)
              for key, _, source in MEASURES}
    first = next(iter(sessions.values()))["study"]
    lines = [f"# User study: {first['scenario']} (scenario hash {first['scenario_hash']})", "",
             f"{counted(len(sessions), 'participant')}: {', '.join(sessions)}. Practice runs "
             f"({PRACTICE_FOLDER}/ in a participant folder) are not counted.", ""]
    incomplete = incomplete_sessions(sessions, practised)
    if incomplete:
        lines += [f"Incomplete: {counted(len(incomplete), 'session')}, each counted for the "
                  "methods it has: " + "; ".join(f"{name} ({lacks})" for name, lacks
                                                 in incomplete.items()) + ".", ""]
    unpaired = answers_without_run(sessions)
    if unpaired:
        lines += ["Answers counted without their run (in the answers' counts and tests, not "
                  "in the trial measures'): " + "; ".join(f"{name} ({what})" for name, what
                                                          in unpaired.items()) + ".", ""]
    lines += ["## Per method", "",
              "| method | participants | success | intervention ratio | task time (s) | "
              "tiredness, median (mean) | ease, median (mean) |", "|---|---|---|---|---|---|---|"]
    for method in methods:
        runs = [s["runs"].get(method) for s in sessions.values()]
        ran = [r for r in runs if r is not None]
        cells = [_summary(values[key][method].values(), source) for key, _, source in MEASURES]
        lines.append(f"| {_label(method)} | {len(ran)} | {sum(bool(r['success']) for r in ran)} "
                     f"of {len(ran)} | {' | '.join(cells)} |")
    scales = "; ".join(f"{key}: {scale_text(key)}" for key in QUESTIONS)
    lines += ["", f"Answers, the count of each value, higher is better ({scales}; Fig. 8, "
              f"{FIG8}):", "", "| method | question | 0 | 1 | 2 | 3 | 4 | 5 |",
              "|---|---|---|---|---|---|---|---|"]
    answers = {name: s["answers"] for name, s in sessions.items()}
    for question, asked in QUESTIONS.items():
        counts = answer_counts(answers, methods, question)
        for method in methods:
            lines.append(f"| {_label(method)} | {asked.text} | "
                         + " | ".join(str(c) for c in counts[method]) + " |")
    pairs = len(methods) * (len(methods) - 1) // 2
    threshold = ALPHA / max(pairs, 1)
    lines += ["", "## Pairwise Wilcoxon signed-rank tests", "",
              "Two-sided, paired by participant (scipy.stats.wilcoxon, its defaults), over "
              "the participants with a value for both methods. Bonferroni correction over "
              f"the {pairs} pairs of each measure: significant when p < {ALPHA:g} / {pairs} "
              f"= {threshold:.4g} (the corrected p is p × {pairs}, at most 1).", "",
              "| measure | pair | n | W | p | corrected p | significant |",
              "|---|---|---|---|---|---|---|"]
    for key, name, source in MEASURES:
        for row in wilcoxon_rows(values[key], methods, source):
            pair = f"{_label(row['pair'][0])} vs {_label(row['pair'][1])}"
            if row["p"] is None:
                lines.append(f"| {name} | {pair} | {row['n']} | - | n/a ({row['note']}) | "
                             "- | - |")
                continue
            note = f" ({row['note']})" if row["note"] else ""
            lines.append(f"| {name} | {pair} | {row['n']} | {row['statistic']:g} | "
                         f"{row['p']:.4g}{note} | {min(1.0, row['p'] * pairs):.4g} | "
                         f"{'yes' if row['p'] < threshold else 'no'} |")
    lines += ["", "## Participants", "", "| participant | order | seed | answers "
              "(tiredness / ease) |", "|---|---|---|---|"]
    for name, session in sessions.items():
        study = session["study"]
        # In the report's order of methods, whichever order the file holds them in.
        by_method = session["answers"]
        in_order = ([m for m in methods if m in by_method]
                    + [m for m in by_method if m not in methods])
        given = "; ".join(f"{_label(m)} {by_method[m].get('tiredness', '-')} / "
                          f"{by_method[m].get('ease', '-')}" for m in in_order) or "none"
        lines.append(f"| {name} | {', '.join(_label(m) for m in study['methods'])} | "
                     f"{study['seed']} | {given} |")
    if damaged:
        lines += ["", f"Skipped as damaged: {counted(len(damaged), 'file')} (named by "
                      "`pbp-drake report`)."]
    return "\n".join(lines) + "\n", sessions, methods, damaged, incomplete


def participant_report(study_dir):
    """Writes STUDY_DIR/results.md and Fig. 8, naming damaged files on stderr. Returns
    `(results text, number of damaged files)`."""
    study_dir = pathlib.Path(study_dir)
    text, sessions, methods, damaged, incomplete = participant_results(study_dir)
    name_damaged(damaged)
    for name, lacks in incomplete.items():
        print(f"pbp-drake: {study_dir / name}: an incomplete session ({lacks}), counted for "
              "the methods it has; its `pbp-drake session` command resumes it", file=sys.stderr,
              flush=True)
    write_atomically(study_dir / "results.md", text)
    plot_questionnaire({name: s["answers"] for name, s in sessions.items()}, methods,
                       study_dir / FIG8)
    return text, len(damaged)
