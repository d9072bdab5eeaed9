"""`make results` (`python -m pbp_drake_bench.results_catalogue`): a study of the list run
into its folder and its table written for the docs, here with one trial per method. The
baselines' page gets each method paired with PBP-Alt and the study's figures beside it."""

import pytest

from pbp_drake_bench.results_catalogue import (
    DOCS_FIGURES, STUDIES, afresh_unless_made_by, code_fingerprint, main)

pytestmark = pytest.mark.slow


def test_a_baselines_study_writes_its_table_paired_with_pbp_alt_and_its_figures(
        repo, tmp_path, monkeypatch):
    monkeypatch.chdir(repo)  # the catalogue names the scenario files from the repository
    generated = tmp_path / "generated"
    assert main(["hsr_reach_baselines", "--trials", "2", "--outputs", str(tmp_path / "out"),
                 "--generated", str(generated)]) == 0
    text = (generated / "hsr_reach_baselines.md").read_text()
    assert text.startswith("`pbp-drake study " + " ".join(
        STUDIES["hsr_reach_baselines"]).replace("30", "2"))
    assert "Each method against PBP-Alt, paired by seed" in text
    for method in ("PBP-Cont", "HOP", "Predict-then-assist", "confidence_alpha", "Teleop"):
        assert f"| task_time | {method} | " in text or f"| success | {method} | " in text
    for figure in DOCS_FIGURES:
        assert (generated / f"hsr_reach_baselines_{figure}").stat().st_size > 10_000


def test_every_baselines_study_has_dragan_and_srinivasas_arbitration():
    """Wherever HOP is compared, confidence_alpha ((1 - alpha) U + alpha P) is too."""
    with_hop = {name: arguments[arguments.index("--methods") + 1].split(",")
                for name, arguments in STUDIES.items()
                if "--methods" in arguments and "hop" in arguments[
                    arguments.index("--methods") + 1].split(",")}
    assert {"hsr_reach_baselines", "hsr_grasp_baselines", "arm_reach_evaluation"} <= set(
        with_hop)
    assert all("confidence_alpha" in methods for methods in with_hop.values())


def test_a_study_folder_resumes_only_from_the_trials_of_todays_code(tmp_path):
    """A folder that other code made (no stamp, or another) is emptied, whose trials would
    put that code's numbers in today's table; one stamped with today's code keeps them."""
    output = tmp_path / "study"
    trial = output / "trials" / "teleop" / "seed_0.json"

    def a_trial_on_disk():
        trial.parent.mkdir(parents=True, exist_ok=True)
        trial.write_text("{}")

    a_trial_on_disk()
    assert afresh_unless_made_by(output, "today")
    assert not trial.exists() and (output / ".code").read_text() == "today"
    a_trial_on_disk()
    assert not afresh_unless_made_by(output, "today")
    assert trial.exists()
    assert afresh_unless_made_by(output, "tomorrow")
    assert not trial.exists() and (output / ".code").read_text() == "tomorrow"


def test_the_code_fingerprint_follows_the_package_and_the_models(tmp_path):
    for root in ("pbp_drake", "models"):
        (tmp_path / root).mkdir()
        (tmp_path / root / "part.py").write_text("x = 1\n")
    first = code_fingerprint(tmp_path)
    (tmp_path / "pbp_drake" / "__pycache__").mkdir()
    (tmp_path / "pbp_drake" / "__pycache__" / "part.pyc").write_bytes(b"compiled")
    assert code_fingerprint(tmp_path) == first
    (tmp_path / "models" / "part.py").write_text("x = 2\n")
    assert code_fingerprint(tmp_path) != first
