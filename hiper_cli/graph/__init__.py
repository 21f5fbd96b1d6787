"""The knowledge base: JSON documents in SQLite (source of truth) and the RDF scene graph.

One public entry: ``open_kb(location) -> KnowledgeBase``.
"""

from hiper_cli.graph.kb import (
    DEFAULT_KB,
    CheckReport,
    KbConfig,
    KnowledgeBase,
    SyncReport,
    is_knowledge_base,
    migrate_kb,
    open_kb,
    open_kb_for_reading,
)

__all__ = [
    "DEFAULT_KB",
    "CheckReport",
    "KbConfig",
    "KnowledgeBase",
    "SyncReport",
    "is_knowledge_base",
    "migrate_kb",
    "open_kb",
    "open_kb_for_reading",
]
