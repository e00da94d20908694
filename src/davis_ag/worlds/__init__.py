"""Stage 13, worlds: a generated scene as other tools read it in 3-D: a USD stage (``usd.py``),
labelled meshes (``mesh.py``) and nerfstudio's posed multi-view layout (``nerfstudio.py``).

``triangles.py`` reopens a scene's geometry with its labels (organ class, fruit id, plant per
triangle) through :mod:`davis_ag.live.reopen`; ``cameras.py`` turns the dataset's poses and
intrinsics into camera-to-world matrices. Every file format of these exports is written here;
docs/worlds.md describes them.
"""
