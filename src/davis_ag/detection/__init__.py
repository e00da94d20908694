"""Stage 12, sim-to-real: DAVIS-Ag as detection data (COCO and YOLO exports, a PyTorch dataset) and detectors."""
