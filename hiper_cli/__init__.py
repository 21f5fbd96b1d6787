"""hiper: a persistent, queryable scene memory for mobile robots, built from RGB-D logs.

The library has one public entry per stage; the CLI (``hiper``) is a thin layer over it.
"""

__version__ = "0.1.0"
DEFAULT_KB = "scene.hiper"  # the knowledge base every command and ``open_kb`` use unless told
__all__ = ["DEFAULT_KB", "__version__"]
