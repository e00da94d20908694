"""davis-ag: generate, read and benchmark DAVIS-Ag active-vision datasets.

Importing the package is light: it loads no stage. The Gymnasium environments are registered by
name (:mod:`davis_ag.environments`) when Gymnasium is already imported, as in
``import gymnasium; import davis_ag``; ``import davis_ag.benchmark`` registers them in any order.
"""

import sys as _sys

__version__ = "0.1.0"

if "gymnasium" in _sys.modules:  # without Gymnasium nothing could make the environments anyway
    from davis_ag.environments import register_environments as _register_environments

    _register_environments()
