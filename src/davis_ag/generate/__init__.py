"""Stage 6, generation: one scene end to end and whole datasets (run configs, presets, the runner,
local pool and Ray executors, dataset-level files), written in the published layout; and a scene
made again from its records (``davis-ag verify SCENE``: ``recorded_settings``, ``regenerate``)."""
