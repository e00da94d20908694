"""Stage 3, formats: the dataset's files: file layout and encodings (``layout``), the one train/test split rule
(``splits``), the instance masks' integer type and no-fruit value (``masks``), the pydantic models of
every JSON file and the dataset config (``models``) and of scene.json (``scene_file``).

Shared by the writer (generate), the reader and validator (data), the benchmark, the exports and
the viewer; after ``scene`` (crop and scenario names), before anything that draws.
"""
