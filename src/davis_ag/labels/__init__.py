"""Stage 3, labels: fruit masks, boxes and visible fractions from a rendered primitive-id image."""
