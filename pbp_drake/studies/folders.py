"""Which study an output folder holds: a method comparison (study.json, trials/) or a 2-D
study (its summary.json), so that one kind is never written into the other's folder."""

import json
import pathlib

from pbp_drake.studies.trial_files import Damage, StudyFolderError, name_damaged

TOY_STUDIES = ("alpha_study", "alt_vs_cont")


def check_folder(output, scenario, digest, participant_condition=None):
    """Raises StudyFolderError when `output` holds a study of another scenario or kind (a 2-D
    study's summary.json, a study.json of another kind), saying so when it was run with
    another `participant_condition`; names a damaged study.json (it is written again).
    Returns the folder's readable study.json as a dict, or None."""
    kind = folder_kind(output)
    if kind is not None and kind != "method_comparison":
        raise StudyFolderError(f"{output} holds a study of kind {kind!r}, not a method "
                               "comparison: choose another --output folder")
    study_path = output / "study.json"
    if not study_path.is_file():
        return None
    try:
        study = json.loads(study_path.read_text())
        problem = None if isinstance(study, dict) else f"holds a {type(study).__name__}"
    except ValueError as error:
        problem = f"truncated or invalid JSON ({error})"
    if problem is not None:
        name_damaged([Damage(str(study_path), f"{problem}; written again")])
        return None
    if study.get("scenario_hash") != digest:
        recorded = study.get("participant_condition")
        condition = ("" if recorded == participant_condition else
                     f"; it was run with --participant-condition {recorded}" if recorded else
                     "; it was run without --participant-condition")
        raise StudyFolderError(
            f"{output} holds a study of another scenario ({study.get('scenario')!r}, hash "
            f"{study.get('scenario_hash')}; this one is {scenario.name!r}, hash {digest}"
            f"{condition}): choose another --output folder")
    return study


def folder_kind(output):
    """Which study a folder holds: "method_comparison" (a study.json or trials/), the kind a
    study.json or summary.json names, or None (no study, or unreadable files)."""
    output = pathlib.Path(output)
    for name in ("study.json", "summary.json"):
        try:
            data = json.loads((output / name).read_text())
        except (OSError, ValueError):
            continue
        if isinstance(data, dict) and isinstance(data.get("study"), str):
            return data["study"]
    return "method_comparison" if (output / "trials").is_dir() else None
