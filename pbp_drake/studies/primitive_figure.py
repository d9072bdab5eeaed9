"""A taught primitive's figure (`pbp-drake teach --figure`): the demonstration, the DMP's
reproduction at its own goal and the shape carried to other goals, from above and from the
side, drawn with matplotlib (headless)."""

import numpy as np

from pbp_drake.core.dmp.primitive import primitive_bank
from pbp_drake.studies.atomic_files import save_figure
from pbp_drake.studies.figures import new_figure

# The rollouts' step (s): fine enough for a smooth line at any task's speed.
STEP = 0.01


def carried_paths(primitive, goals):
    """The DMPs' open-loop paths `(1 + K, T, 3)` from the demonstration's start, over its
    duration: to its own goal first, then to each of `goals` (K, 3)."""
    targets = np.vstack([primitive.goal, np.asarray(goals, float).reshape(-1, 3)])
    bank = primitive_bank(primitive, primitive.start, len(targets))
    phase, _, velocity = bank.initial_state()
    steps = int(np.ceil(primitive.duration / STEP))
    return bank.predict(phase, primitive.start[:, None], velocity,
                        bank.goals_matrix(targets), primitive.duration / steps, steps)


def plot_primitive(primitive, goals, path):
    """Writes the figure to `path` (the module's docstring); `goals` (K, 3) are where the
    shape is carried (the scene's objects)."""
    paths = carried_paths(primitive, goals)
    figure, axes = new_figure(1, 2, figsize=(11, 4.2))
    for axis, (i, j), view in zip(axes, ((0, 1), (0, 2)), ("from above", "from the side")):
        axis.plot(primitive.positions[:, i], primitive.positions[:, j], ".", ms=3,
                  color="0.55", label="demonstration")
        axis.plot(paths[0][:, i], paths[0][:, j], color="tab:blue", lw=2,
                  label=f"reproduction ({primitive.fit_error * 1000:.1f} mm RMS)")
        for index, carried in enumerate(paths[1:]):
            axis.plot(carried[:, i], carried[:, j], color="tab:orange", lw=1,
                      label="carried to other goals" if index == 0 else None)
            axis.plot(carried[-1, i], carried[-1, j], "o", color="tab:orange", ms=5)
        axis.plot(*primitive.start[[i, j]], "s", color="black", ms=6, label="start")
        axis.set_xlabel("xyz"[i] + " (m)")
        axis.set_ylabel("xyz"[j] + " (m)")
        axis.set_title(view)
        axis.set_aspect("equal", adjustable="datalim")
    axes[0].legend(loc="best", fontsize=8)
    figure.suptitle(f"A taught primitive ({primitive.settings.formulation}, "
                    f"{primitive.settings.basis_count} basis functions)")
    figure.tight_layout()
    save_figure(figure, path, dpi=110)
