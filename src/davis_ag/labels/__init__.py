"""Stage 5, labels: fruit masks, boxes and visible fractions from a rendered primitive-id image."""
