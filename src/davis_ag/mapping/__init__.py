"""Stage 10, mapping: see every fruit of a row segment within a motion budget (``davis_ag/RowMapping-v0``).

The task the agricultural view planners are scored on: an episode starts at a view of a row
segment, each step is one of the grid's moves, and the agent is rewarded for fruit it sees for the
first time. :mod:`coverage` says which fruit the segment has and which view sees which;
:mod:`bound` the most any episode of a budget can see; :mod:`env` is the environment;
:mod:`baselines` the fixed sweep, Rand and the greedy planner; :mod:`evaluation` and
:mod:`results` score policies into a results file that ``compare`` ranks and ``verify`` replays.
"""
