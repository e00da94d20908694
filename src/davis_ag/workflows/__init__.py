"""Stage 15, workflows: the jobs composed from the stages before, one role each.

``stages`` holds the helpers the jobs share (generate scenes, choose the split, run the
baselines); ``demo``, ``reproduce/`` (with the pages it writes), ``bench/``, ``scene_stats/`` and
``transfer`` each import only ``stages`` and their own modules.
"""
