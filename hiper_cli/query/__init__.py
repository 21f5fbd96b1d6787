"""The query layer: ask the scene memory in plain words, SPARQL or Python, get typed answers.

Verbs (``verbs.py``): ``find``, ``count``, ``last_seen``, ``when``, ``trajectory``; plus
``workspace`` (``workspace.py``), ``describe`` (``describe.py``) and ``ask`` (a plain-words
query through the grammar of ``grammar.py``). Named SPARQL queries live in ``queries/*.rq``.
"""

from hiper_cli.query.ask import ask
from hiper_cli.query.grammar import ParsedQuery, parse
from hiper_cli.query.results import SCHEMA_VERSION, Answer, GoalPose, Hit, Sighting, Trajectory
from hiper_cli.query.spec import Near, On, QueryConfig, QuerySpec
from hiper_cli.query.verbs import count, find, last_seen, trajectory, when

__all__ = [
    "SCHEMA_VERSION",
    "Answer",
    "GoalPose",
    "Hit",
    "Near",
    "On",
    "ParsedQuery",
    "QueryConfig",
    "QuerySpec",
    "Sighting",
    "Trajectory",
    "ask",
    "count",
    "find",
    "last_seen",
    "parse",
    "trajectory",
    "when",
]
