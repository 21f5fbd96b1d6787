"""Synthetic long-term RGB-D logs with ground truth (``hiper sim``)."""
