"""Measurements against ground truth: the paper's tables, ours beside them."""
