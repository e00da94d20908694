"""Stage 8, robot: real arms on a base in the alley, which views they reach and what moves cost.

A robot is an arm of example-robot-data (or a URDF) on a base driving along the scene's base line
with an optional lift and a wrist camera (:mod:`~davis_ag.robot.definitions`, built-in robots in
``robot/robots/``); pinocchio models it and coal checks its collisions (:mod:`~davis_ag.robot.model`),
its IK is pinocchio's (:mod:`~davis_ag.robot.ik`), the scene's trunks are its obstacles
(:mod:`~davis_ag.robot.obstacles`), and :mod:`~davis_ag.robot.reach` solves every view of a scene
once and caches it. After ``data`` (it reads generated scenes), before ``benchmark``, which
restricts its moves to a robot's reach. Nothing here imports Helios.
"""

from davis_ag.robot.definitions import RobotDefinition, builtin_robots, load_robot

__all__ = ["RobotDefinition", "builtin_robots", "load_robot"]
