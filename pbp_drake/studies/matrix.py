"""The folder of every method under every pilot (`pbp-drake study FILE --pilots ...`, run by
`comparison.run_method_matrix`): its study.json, a study folder per pilot
(`DIR/pilots/<pilot>/`, whose scenario hash includes the pilot) and its summary read from
the pilots' trial files. The layout is in docs/tasks/studies.md ("Every method under
every pilot").
"""

import json
import pathlib

from pbp_drake.scenarios import ScenarioError
from pbp_drake.scenarios.pilots import PILOT_NAMES, check_pilot_name
from pbp_drake.studies.atomic_files import read_text
from pbp_drake.studies.folders import MATRIX
from pbp_drake.studies.summary import summarize
from pbp_drake.studies.trial_files import (
    TRIAL_FORMAT, StudyFolderError, name_damaged, read_study, write_study_json)

PILOTS_FOLDER = "pilots"
# Summary fields every pilot's study shares with the matrix: said once, at its top.
_SHARED = ("study", "scenario", "trials", "seed", "split", "seeds", "measures_collisions",
           "collision_histogram_edges")


def pilot_folder(output, pilot):
    """The study folder of one pilot in a matrix folder."""
    return pathlib.Path(output) / PILOTS_FOLDER / pilot


def check_pilots(pilots, option="--pilots"):
    """Raises ScenarioError for an unknown pilot (with did-you-mean), a pilot named twice
    or no pilot at all."""
    if not pilots:
        raise ScenarioError(f"{option}: name at least one of {', '.join(PILOT_NAMES)}")
    for pilot in pilots:
        check_pilot_name(pilot, option)
    if len(set(pilots)) != len(pilots):
        raise ScenarioError(f"{option} {','.join(pilots)} names a pilot twice")


def write_matrix_study(output, scenario, digest, methods, pilots, trials, seed, split=None,
                       scenario_file=None, split_seeds=None, overrides=None):
    """Writes a matrix folder's study.json (each pilot's folder has its own)."""
    study = {"study": MATRIX, "format": TRIAL_FORMAT, "scenario": scenario.name,
             "scenario_hash": digest, "methods": list(methods), "pilots": list(pilots),
             "trials": trials, "seed": seed, "split": split}
    write_study_json(output, study, scenario_file, split_seeds, overrides=overrides)


def read_matrix_study(output):
    """A matrix folder's study.json; StudyFolderError when missing, damaged or not a matrix's."""
    path = pathlib.Path(output) / "study.json"
    try:
        study = json.loads(read_text(path))
    except (OSError, ValueError) as error:
        raise StudyFolderError(f"{path}: cannot be read as a matrix's study ({error})") from None
    pilots = study.get("pilots") if isinstance(study, dict) else None
    if (not isinstance(study, dict) or study.get("study") != MATRIX
            or not isinstance(pilots, list) or not all(isinstance(p, str) for p in pilots)):
        raise StudyFolderError(f"{path}: not the study.json of a matrix of methods and pilots")
    return study


def read_matrix(output):
    """The matrix's study.json and `{pilot: read_study(its folder)}`, naming damaged files."""
    study = read_matrix_study(output)
    pilots = {}
    for pilot in study["pilots"]:
        pilots[pilot] = read_study(pilot_folder(output, pilot))
        name_damaged(pilots[pilot][2])
    return study, pilots


def summarize_matrix(study, pilots, output):
    """The matrix's summary: the fields every pilot's study shares (`_SHARED`), then
    `"pilots": {NAME: that pilot's summary without them}`, and every damaged file."""
    summary = {"study": MATRIX, "scenario": study["scenario"],
               "scenario_hash": study["scenario_hash"]}
    damaged = []
    for pilot, (pilot_study, records, broken) in pilots.items():
        folder = pilot_folder(output, pilot)
        pilot_summary = summarize(pilot_study, records, broken, folder)
        if "trials" not in summary:
            summary.update({key: pilot_summary[key] for key in _SHARED[2:]
                            if key in pilot_summary})
        summary.setdefault("pilots", {})[pilot] = {
            key: value for key, value in pilot_summary.items()
            if key not in _SHARED and key != "damaged"}
        damaged += [{**item, "file": f"{PILOTS_FOLDER}/{pilot}/{item['file']}"}
                    for item in pilot_summary["damaged"]]
    summary["damaged"] = damaged
    return summary
