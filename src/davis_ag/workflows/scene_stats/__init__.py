"""``davis-ag scene-stats``: each crop's plants and scenes measured (``stats``) and written into
docs/scenes.md and docs/crops.md (``page``, ``library_crops``)."""
