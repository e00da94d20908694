"""``davis-ag bench``: the performance benchmarks as ratios against a reference run in the same
process (``run``), with the new crops' rows (``crops``), training (``training``), ``verify``'s rate
(``verify``), the shared timing loop (``timing``) and the JSON and docs/performance.md report (``report``)."""
