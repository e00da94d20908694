"""Stage 4, drawing: renderers that turn a scene and a viewpoint into colour and primitive-id images."""
