"""The dataset's formats: file layout and encodings (``layout``), the one train/test split rule
(``splits``) and the pydantic models of every JSON file and the dataset config (``models``).

Shared by the writer (generate), the reader and validator (data), the benchmark, the exports and
the viewer; after ``scene`` (crop and scenario names), before anything that draws.
"""
