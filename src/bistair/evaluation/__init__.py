"""Judging decodes: scores against ground truth, the comparison of every method on one
scene (the benchmark), figures, point-cloud views and the HTML report."""
