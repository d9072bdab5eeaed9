"""The per-tick time series of an HSR task as CSV: its columns and rows, one row per control
tick. A study's trial files (`pbp_drake.studies.trial_files`) and a run streamed to disk
(`pbp_drake.builder.streamed_run`) write the same format with these functions."""

import numpy as np


# The hand's orientation in the grasping task, a unit quaternion w, x, y, z
# (`TaskResult.hand_orientations`: what `pbp-drake teach` fits a pose from); a trial file
# may end without these columns.
HAND_ORIENTATION_COLUMNS = ["hand_qw", "hand_qx", "hand_qy", "hand_qz"]
# The grasping task's orientation columns (`TaskResult.angles_to_target`, degrees; the
# commanded and the operator's angular velocities, rad/s, world frame; the hand's).
GRASP_COLUMNS = ["angle_to_target", "command_wx", "command_wy", "command_wz",
                 "operator_wx", "operator_wy", "operator_wz", *HAND_ORIENTATION_COLUMNS]


def time_series_columns(has_collision, has_grasp=False):
    return ["time", "ee_x", "ee_y", "ee_z", "heading",
            "command_x", "command_y", "command_z", "command_vx", "command_vy", "command_vz",
            "command_heading", "operator_active",
            "operator_vx", "operator_vy", "operator_vz", "operator_yaw_rate",
            "selected_goal", "target"] + (["in_collision"] if has_collision else []) + (
            GRASP_COLUMNS if has_grasp else [])


def time_series_header(has_collision, has_grasp=False):
    """The CSV's header line, newline included."""
    return ",".join(time_series_columns(has_collision, has_grasp)) + "\n"


def _has_grasp(series):
    return getattr(series, "angles_to_target", None) is not None


def time_series_rows(series):
    """The CSV lines (newlines included, no header) of the per-tick series of `series`: a
    TaskResult, or any object with its time series attributes. Floats are written in their
    shortest exact form (repr), so reading them back gives the same numbers."""
    has_collision = series.in_collision is not None
    has_grasp = _has_grasp(series)
    # Python lists, not a numpy scalar per cell: the same doubles' repr, faster.
    times, ee, headings, commands, active, operator, selected, targets = (
        np.asarray(values).tolist() for values in (
            series.times, series.ee_positions, series.headings, series.commands,
            series.operator_active, series.operator_commands, series.selected_goals,
            series.targets))
    collisions = np.asarray(series.in_collision).tolist() if has_collision else None
    if has_grasp:
        angles, angular, twists, hand = (np.asarray(values).tolist() for values in (
            series.angles_to_target, series.command_angular_velocities,
            np.asarray(series.operator_twists)[:, 3:], series.hand_orientations))
    lines = []
    for k in range(len(times)):
        row = [times[k], *ee[k], headings[k], *commands[k]]
        row = [repr(float(x)) for x in row]
        row.append(str(int(bool(active[k]))))
        row += [repr(float(x)) for x in operator[k]]
        row += [str(int(selected[k])), str(int(targets[k]))]
        if has_collision:
            row.append(str(int(bool(collisions[k]))))
        if has_grasp:
            row += [repr(float(x)) for x in (angles[k], *angular[k], *twists[k], *hand[k])]
        lines.append(",".join(row) + "\n")
    return "".join(lines)


def time_series_csv(result):
    """The per-tick time series of a TaskResult as CSV text, header first."""
    return (time_series_header(result.in_collision is not None, _has_grasp(result))
            + time_series_rows(result))
