"""Loads our primitive-shape Toyota HSR model (``hsr/hsrb_primitive.urdf``, written from
published kinematic facts; docs/tasks/hsr-station.md, "The model") into a MultibodyPlant.

Example::

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    hsr = add_hsr(plant)
    plant.Finalize()
"""

from pathlib import Path

from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant_
from pydrake.multibody.tree import ModelInstanceIndex

PACKAGE_NAME = "pbp_drake_models"
HSR_URL = "package://pbp_drake_models/hsr/hsrb_primitive.urdf"

# The base's joints, in the order of its (x, y, yaw) pose.
BASE_JOINT_NAMES = ("base_x_joint", "base_y_joint", "base_yaw_joint")
TORSO_JOINT_NAME = "torso_lift_joint"
# The torso is not actuated: the coupler keeps torso = ratio * arm_lift.
TORSO_TO_ARM_LIFT_RATIO = 0.5
ARM_JOINT_NAMES = (
    "arm_lift_joint",
    "arm_flex_joint",
    "arm_roll_joint",
    "wrist_flex_joint",
    "wrist_roll_joint",
)
# The end-effector frame, between the fingertips, its z axis out of the hand.
END_EFFECTOR_FRAME = "hand_ee_link"
# HSR's "neutral" pose (arm up, hand facing forward), in ARM_JOINT_NAMES order.
NEUTRAL_ARM_POSITIONS = (0.0, 0.0, 0.0, -1.57, 0.0)
# Every joint with a motor, base first; a motor is named after its joint ("_motor").
ACTUATED_JOINT_NAMES = BASE_JOINT_NAMES + ARM_JOINT_NAMES


def models_dir() -> Path:
    """The folder that holds the ``pbp_drake_models`` package: an installed wheel's
    ``pbp_drake/_models`` or, failing that, a source checkout's top-level ``models/``."""
    package_root = Path(__file__).resolve().parent.parent  # .../pbp_drake
    candidates = (package_root / "_models", package_root.parent / "models")
    for folder in candidates:
        if (folder / PACKAGE_NAME / "package.xml").is_file():
            return folder
    raise FileNotFoundError(
        f"Cannot find the {PACKAGE_NAME} models: looked for "
        + " and ".join(str(c / PACKAGE_NAME / "package.xml") for c in candidates)
        + ". Reinstall pbp_drake or run from a full checkout."
    )


def configure_parser(parser: Parser) -> None:
    """Lets ``parser`` resolve ``package://pbp_drake_models/...`` from local files (offline);
    calling this twice on one parser is harmless."""
    package_xml = models_dir() / PACKAGE_NAME / "package.xml"
    parser.package_map().AddPackageXml(str(package_xml))


def add_hsr(plant, parser: Parser | None = None) -> ModelInstanceIndex:
    """Adds the HSR to ``plant`` (not finalized yet; a discrete plant with the SAP or
    lagged contact approximation enforces the torso coupler) and returns its model
    instance. ``parser``: a Parser for ``plant`` (e.g. one with auto-renaming to add
    several robots); a new one otherwise."""
    # Drake's parser aborts the interpreter (a failed C++ assertion) on either.
    if parser is None and not MultibodyPlant_.is_subclass_of_instantiation(type(plant)):
        raise ValueError(f"plant must be a MultibodyPlant, got {type(plant).__name__}")
    if (parser.plant() if parser is not None else plant).is_finalized():
        raise ValueError("plant is finalized: call add_hsr(plant) before plant.Finalize()")
    parser = parser or Parser(plant)
    configure_parser(parser)
    (model,) = parser.AddModels(url=HSR_URL)
    return model


def actuator_name(joint_name: str) -> str:
    """The name of the motor on ``joint_name`` (the model's transmissions follow it)."""
    return joint_name.replace("_joint", "_motor")
