"""The fault suite: a corpus of bad inputs, damaged stores and crashes, generated in code."""
