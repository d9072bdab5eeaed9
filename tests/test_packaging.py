"""The built wheel carries the robot models: the HSR loads from an install outside the
checkout."""

import subprocess
import sys
import sysconfig
import textwrap

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


def test_the_wheel_ships_the_models(repo, tmp_path):
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(repo)], check=True, timeout=240)
    (wheel,) = wheels.glob("pbp_drake-*.whl")
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
