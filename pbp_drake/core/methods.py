"""The registry of shared-control methods: what a scenario's `method: NAME` runs, by name.
Every layer reads a method's `Method` entry in `METHODS`; none compares its name.
`register_method` adds one at run time (docs/concepts/pbp.md, "Your own method").
"""

import dataclasses
import typing

from pbp_drake.core.arbitration import BLEND_LAWS
from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.hindsight_optimization import ASSISTANCE_WEIGHTS


#: `Method.policy`: the goal estimator, the DMP bank and a blender ...
BLENDED = "blended"
#: ... or HOP's posterior and its assistance, added to the operator's command.
ASSISTED = "assisted"


def _always(settings):
    return True


def _never(settings):
    return False


def _while_assisting(settings):
    return bool(getattr(settings, "assistance", True))


@dataclasses.dataclass(frozen=True)
class Method:
    """One registry entry. Exactly one of `blend_mode` and `assistance` is set: a method
    either blends the operator with its DMPs' reference by a law of `BLEND_LAWS` or adds
    an assistance of `ASSISTANCE_WEIGHTS` to the operator's command (no DMPs)."""

    #: The name scenario files and `--method` spell.
    name: str
    #: What a person reads: the page's Start button, the results tables, the figures.
    label: str
    #: Its colour in the figures (a Matplotlib colour).
    colour: str
    #: The blending law (a key of `pbp_drake.core.arbitration.BLEND_LAWS`), or None.
    blend_mode: typing.Optional[str] = None
    #: HOP's assistance (a key of `ASSISTANCE_WEIGHTS`), or None.
    assistance: typing.Optional[str] = None
    #: The family it belongs to: pbp, arbitration, teleop or baseline.
    family: str = "pbp"
    #: The DMP bank holds its phase while the operator acts (PBP-Alt).
    lock_phase: bool = False
    #: The operator's forward key works (the paper disables it under PBP and arbitration).
    forward_key: bool = False
    #: An operator drives (PBP-NoUser: none, the robot runs alone).
    operated: bool = True
    #: The scenario field that holds its own settings (`alpha`, `hop`), or None.
    settings: typing.Optional[str] = None
    #: Whether the page shows the robot's intent, given those settings.
    shows_intent: typing.Callable = _always
    #: In the 2-D scenes its policy is the demonstration played open loop, not the DMPs.
    plays_demonstration: bool = False
    #: Why it runs only in the robot tasks (empty: it runs in the 2-D scenes too).
    task_only: str = ""

    def __post_init__(self):
        if (self.blend_mode is None) == (self.assistance is None):
            raise ValueError(f"method {self.name!r}: give a blend_mode or an assistance, "
                             f"not both nor neither")
        if self.blend_mode is not None and self.blend_mode not in BLEND_LAWS:
            raise ValueError(f"method {self.name!r}: blend_mode {self.blend_mode!r} is not "
                             f"one of {tuple(BLEND_LAWS)}")
        if self.assistance is not None and self.assistance not in ASSISTANCE_WEIGHTS:
            raise ValueError(f"method {self.name!r}: assistance {self.assistance!r} is not "
                             f"one of {tuple(ASSISTANCE_WEIGHTS)}")

    @property
    def policy(self):
        """What the builder builds for it: the DMPs and a blender (`BLENDED`), or HOP's
        assistance (`ASSISTED`)."""
        return BLENDED if self.assistance is None else ASSISTED

    @property
    def takes_weight(self):
        """Its label may carry a weight, `NAME=A` (its settings are the scenario's alpha)."""
        return self.settings == "alpha"


METHODS = {method.name: method for method in (
    Method("pbp_alternated", "PBP-Alt", "tab:orange", blend_mode="pbp_alternated",
           lock_phase=True),
    Method("pbp_continuous", "PBP-Cont", "tab:blue", blend_mode="pbp_continuous"),
    Method("fixed_alpha", "Fixed alpha", "tab:purple", blend_mode="fixed_alpha",
           family="arbitration", settings="alpha", plays_demonstration=True),
    # No name in the papers: it reads as `--methods` spells it.
    Method("confidence_alpha", "confidence_alpha", "tab:cyan", blend_mode="confidence_alpha",
           family="arbitration", task_only="needs a goal estimator's confidence"),
    # The robot never moves by itself: no intent to show.
    Method("teleop", "Teleop", "tab:green", blend_mode="teleop", family="teleop",
           forward_key=True, shows_intent=_never),
    Method("pbp_no_user", "PBP-NoUser", "tab:gray", blend_mode="pbp_continuous",
           operated=False),
    # The shared-autonomy baselines (Javdani et al.'s names): their assistance adds to a
    # full command, so the forward key works; with it off they add nothing to show.
    Method("hop", "HOP", "tab:red", assistance="hop", family="baseline", forward_key=True,
           settings="hop", shows_intent=_while_assisting,
           task_only="assists toward the HSR tasks' goals"),
    Method("predict_then_assist", "Predict-then-assist", "tab:brown",
           assistance="predict_then_assist", family="baseline", forward_key=True,
           settings="hop", shows_intent=_while_assisting,
           task_only="assists toward the HSR tasks' goals"),
)}


def register_method(method):
    """Adds `method` (a `Method`) to `METHODS` under its name; ValueError if taken."""
    if not isinstance(method, Method):
        raise ValueError(f"method must be a Method, got {type(method).__name__}")
    if method.name in METHODS:
        raise ValueError(f"method {method.name!r} is already registered")
    METHODS[method.name] = method
    return method


def method_entry(name, field="method"):
    """The `Method` called `name`; ValueError naming `field`, the choices and the nearest
    one for an unknown name."""
    if name not in METHODS:
        raise ValueError(unknown_choice(field, name, METHODS))
    return METHODS[name]


def method_colour(name, default=None):
    """The method's colour in the figures; `default` for an unknown name."""
    return METHODS[name].colour if name in METHODS else default


def methods_of(family, operated=True):
    """The names of the methods of `family` (registry order), by default those an operator
    drives: `methods_of("pbp")` is PBP-Alt and PBP-Cont."""
    return tuple(name for name, method in METHODS.items()
                 if method.family == family and method.operated == operated)


def forward_key_enabled(scenario):
    """Whether the method of `scenario` (anything with a `method` name) enables the
    operator's forward key (a person's keys, and the virtual participant's input)."""
    return method_entry(scenario.method).forward_key


def shows_intent(scenario):
    """Whether the page shows the robot's intent (the blue ball over the object it means)
    under the method of `scenario`, read with the method's own settings field."""
    method = method_entry(scenario.method)
    settings = getattr(scenario, method.settings) if method.settings else None
    return method.shows_intent(settings)
