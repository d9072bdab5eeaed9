"""The PBP loop's systems (DMP banks, goal estimators and grouping, blenders, hand-over), in
position form and six-DoF pose form (`Pose...`), their sources and helpers, and the
shared-autonomy baselines' systems (`MaxEntGoalEstimator`, `HopAssistance` and their
pose twins)."""

from pbp_drake.systems.pbp.blender import Blender
from pbp_drake.systems.pbp.demonstration_player import DemonstrationPlayer
from pbp_drake.systems.pbp.dmp_bank import DmpBank
from pbp_drake.systems.pbp.goal_estimator import GoalEstimator
from pbp_drake.systems.pbp.goal_grouping import GoalGrouping, PoseGoalGrouping
from pbp_drake.systems.pbp.goals_source import GoalsSource
from pbp_drake.systems.pbp.hand_over import HandOver
from pbp_drake.systems.pbp.heading_command import HeadingCommand
from pbp_drake.systems.pbp.hop_assistance import HopAssistance
from pbp_drake.systems.pbp.likely_goals import LikelyGoals
from pbp_drake.systems.pbp.intent_filter_estimator import (
    IntentFilterGoalEstimator, PoseIntentFilterGoalEstimator)
from pbp_drake.systems.pbp.maxent_goal_estimator import MaxEntGoalEstimator
from pbp_drake.systems.pbp.pose_blender import PoseBlender
from pbp_drake.systems.pbp.pose_dmp_bank import PoseDmpBank
from pbp_drake.systems.pbp.pose_goal_estimator import PoseGoalEstimator
from pbp_drake.systems.pbp.pose_hand_over import PoseHandOver
from pbp_drake.systems.pbp.pose_hop_assistance import PoseHopAssistance
from pbp_drake.systems.pbp.pose_maxent_goal_estimator import PoseMaxEntGoalEstimator

__all__ = ["Blender", "DemonstrationPlayer", "DmpBank", "GoalEstimator", "GoalGrouping",
           "GoalsSource", "HandOver", "HeadingCommand", "HopAssistance",
           "IntentFilterGoalEstimator", "LikelyGoals", "MaxEntGoalEstimator", "PoseBlender",
           "PoseDmpBank", "PoseGoalEstimator", "PoseGoalGrouping",
           "PoseIntentFilterGoalEstimator", "PoseHandOver", "PoseHopAssistance",
           "PoseMaxEntGoalEstimator"]
