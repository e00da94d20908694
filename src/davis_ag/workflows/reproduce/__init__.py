"""``davis-ag reproduce``: the paper's experiments end to end, resumable stage by stage.

``configs`` (what a run makes), ``groups`` (its scenario and crop groups), ``learners`` (A2C and
PPO trained and kept), ``clock`` (how long each stage took, on what machine), ``state`` (the run's
state.json), ``run`` (the stages in order), ``status`` (what a run has done and has left), and
``pages/``, the pages the run writes (docs/results.md, docs/crops.md) from its records.
"""
