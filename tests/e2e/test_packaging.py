"""The built wheel carries the robot models: the HSR loads from an install outside the
checkout, and the wheel installed into a new venv runs the HSR task from another folder."""

import os
import subprocess
import sys
import sysconfig
import textwrap

import pytest

# Whole tasks, studies, notebooks, browsers or pip: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

LOAD_THE_HSR = textwrap.dedent("""
    import pathlib
    from pydrake.multibody.plant import MultibodyPlant
    import pbp_drake
    from pbp_drake.robots.hsr_model import add_hsr, models_dir
    plant = MultibodyPlant(0.001)
    add_hsr(plant)
    plant.Finalize()
    print(pathlib.Path(pbp_drake.__file__).parent, models_dir(), plant.num_positions())
""")


@pytest.fixture(scope="module")
def wheel(repo, tmp_path_factory):
    wheels = tmp_path_factory.mktemp("wheels")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels),
                    str(repo)], check=True, timeout=240)
    (built,) = wheels.glob("pbp_drake-*.whl")
    return built


def test_the_wheel_ships_the_models(wheel, tmp_path):
    target = tmp_path / "installed"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(target), str(wheel)], check=True, timeout=120)
    # Run from an empty folder with only the install and the venv's own packages (drake)
    # on the path, so that nothing of the checkout can be found.
    site_packages = sysconfig.get_paths()["purelib"]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    result = subprocess.run(
        [sys.executable, "-I", "-c",
         f"import sys; sys.path[:0] = [{str(target)!r}, {site_packages!r}]\n" + LOAD_THE_HSR],
        cwd=elsewhere, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    package, models, positions = result.stdout.split()
    assert package.startswith(str(target)) and models.startswith(str(target))
    assert int(positions) >= 9


@pytest.fixture(scope="module")
def fresh_venv(wheel, tmp_path_factory):
    """A new venv in a temporary folder with the wheel installed into it.

    Its dependencies (drake, numpy, matplotlib, scipy) come from this venv through a `.pth` file
    that adds this venv's site-packages as a plain path: no network, and none of this venv's
    own `.pth` files (such as the checkout's editable install) take effect there.
    """
    venv = tmp_path_factory.mktemp("fresh") / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True,
                   timeout=120)
    python = venv / "bin" / "python"
    site_packages = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True, capture_output=True, text=True).stdout.strip()
    ours = {sysconfig.get_paths()[name] for name in ("purelib", "platlib")}
    with open(os.path.join(site_packages, "project_dependencies.pth"), "w") as pth:
        pth.write("".join(f"{path}\n" for path in sorted(ours)))
    # Without PYTHONPATH: where it names the checkout (its pbp_drake.egg-info), pip would
    # find pbp_drake installed in the new venv already and install nothing.
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install",
                    "--no-deps", "--no-index", "-q", str(wheel)], check=True, timeout=240,
                   env=_elsewhere_env())
    return venv


def _elsewhere_env():
    """This environment without what would lead another Python to this checkout or venv."""
    return {key: value for key, value in os.environ.items()
            if key not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}


def _elsewhere(tmp_path):
    folder = tmp_path / "elsewhere"
    folder.mkdir()
    return folder, _elsewhere_env()


def test_the_installed_wheel_runs_the_hsr_task_outside_the_checkout(repo, fresh_venv,
                                                                      tmp_path):
    cwd, env = _elsewhere(tmp_path)
    script = fresh_venv / "bin" / "pbp-drake"
    # The command runs the new venv's interpreter, so it imports the installed wheel.
    assert script.read_text().splitlines()[0] == f"#!{fresh_venv / 'bin' / 'python'}"
    result = subprocess.run(
        [str(script), "run", str(repo / "diagrams" / "hsr_reach.yaml"),
         "--operator", "virtual", "--headless", "--duration", "30"],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    line = result.stdout.strip().splitlines()[-1]
    assert line.startswith("hsr_reach [pbp_alternated, seed 0]: success in "), line
    assert "intervention ratio" in line


def test_the_installed_package_is_the_wheel_and_its_version_is_single_sourced(
        repo, fresh_venv, tmp_path):
    cwd, env = _elsewhere(tmp_path)
    script = textwrap.dedent("""
        import importlib.metadata, pathlib
        import pbp_drake
        from pbp_drake.robots.hsr_model import models_dir
        print(pathlib.Path(pbp_drake.__file__).parent)
        print(models_dir())
        print(pbp_drake.__version__, importlib.metadata.version("pbp_drake"))
    """)
    result = subprocess.run([str(fresh_venv / "bin" / "python"), "-c", script], cwd=cwd,
                            env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    package, models, versions = result.stdout.strip().splitlines()
    assert package.startswith(str(fresh_venv)) and models.startswith(str(fresh_venv))
    module_version, metadata_version = versions.split()
    assert module_version == metadata_version
    assert f'__version__ = "{module_version}"' in (repo / "pbp_drake" / "__init__.py").read_text()


def test_python_dash_m_is_the_same_command(fresh_venv, tmp_path):
    cwd, env = _elsewhere(tmp_path)
    by_module = subprocess.run([str(fresh_venv / "bin" / "python"), "-m", "pbp_drake", "--help"],
                               cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    by_script = subprocess.run([str(fresh_venv / "bin" / "pbp-drake"), "--help"], cwd=cwd,
                               env=env, capture_output=True, text=True, timeout=120)
    assert by_module.returncode == by_script.returncode == 0, by_module.stderr
    assert by_module.stdout == by_script.stdout
    assert "run" in by_module.stdout and "study" in by_module.stdout


def test_every_public_name_imports_from_the_package():
    import pbp_drake

    for name in pbp_drake.__all__:
        assert getattr(pbp_drake, name) is not None, name


def test_importing_the_package_does_not_import_drake():
    result = subprocess.run(
        [sys.executable, "-c", "import sys, pbp_drake, pbp_drake.core.dmp; "
         "print('pydrake' in sys.modules)"], capture_output=True, text=True, timeout=60)
    assert result.stdout.strip() == "False", result.stderr


def test_the_bench_runs_as_a_module_and_as_a_command():
    by_module = subprocess.run([sys.executable, "-m", "pbp_drake_bench", "--help"],
                               capture_output=True, text=True, timeout=120)
    by_command = subprocess.run([sys.executable, "-m", "pbp_drake", "bench", "--help"],
                                capture_output=True, text=True, timeout=120)
    assert by_module.returncode == by_command.returncode == 0, by_module.stderr
    assert by_module.stdout == by_command.stdout
    assert "usage: pbp-drake bench" in by_module.stdout
