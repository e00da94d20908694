"""Stage 14, pictures: contact sheets, plots and the HTML report of a dataset and its benchmark."""
