"""The pages ``davis-ag reproduce`` writes from a run's records: docs/results.md (``results`` with
``blocks``, ``gaps``, ``policies``, ``provenance`` and ``paper_table4``) and docs/crops.md (``crops``)."""
