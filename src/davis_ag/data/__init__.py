"""Stage 7, reading: the published DAVIS-Ag layout (ours and the original download), its schema and
validation."""
