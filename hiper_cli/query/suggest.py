"""The refusal of a query the grammar cannot read: it quotes every word not understood, says
when one is a place name (hiper keeps no named places), and offers a question that parses.

A word is replaced by a known one only when the two are near relative to the word's length
(at most one edit, a swap of neighbours counting as one, for words of 4-7 letters, two from 8
letters, none below 4): "chiars" -> "chairs", never "count" -> "computer" or "kitchen" ->
"kite". Other unknown words are dropped with the prepositions that led to them ("cups in the
kitchen" -> "cups"). When the result does not parse, the suggestion is built from what was
understood ("how many chairs").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import cache

from hiper_cli.query.vocabulary import PLACE_WORDS, class_words

__all__ = ["edit_distance", "max_edits", "nearest_word", "refusal"]

_LEADING = frozenset(["in", "at", "on", "near", "from", "to", "the", "a", "an", "of", "inside", "into", "my"])


def edit_distance(a: str, b: str) -> int:
    """Edits (insert, delete, substitute, swap two neighbours) turning ``a`` into ``b``."""
    prev2: list[int] = []
    prev = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        row = [i] + [0] * len(b)
        for j in range(1, len(b) + 1):
            cost = 0 if a[i - 1] == b[j - 1] else 1
            row[j] = min(prev[j] + 1, row[j - 1] + 1, prev[j - 1] + cost)
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                row[j] = min(row[j], prev2[j - 2] + 1)
        prev2, prev = prev, row
    return prev[-1]


def max_edits(word: str) -> int:
    """How many edits a typo of ``word`` may hold: none below 4 letters, one up to 7, then two."""
    return 0 if len(word) < 4 else 1 if len(word) < 8 else 2


@cache
def _vocabulary() -> tuple[str, ...]:
    from hiper_cli.query import grammar

    words = grammar.keywords()
    for phrase in class_words():
        words.update(phrase.split())
    return tuple(sorted(w for w in words if w.isalpha() and w not in PLACE_WORDS))


def nearest_word(word: str, vocabulary: Sequence[str] | None = None) -> str | None:
    """The known word within ``max_edits`` of ``word`` (fewest edits, then the same first
    letter, then alphabetical), or None."""
    limit = max_edits(word)
    if limit == 0:
        return None
    best: tuple[int, int, str] | None = None
    for known in vocabulary if vocabulary is not None else _vocabulary():
        if abs(len(known) - len(word)) > limit:
            continue
        d = edit_distance(word, known)
        if d <= limit and (key := (d, known[0] != word[0], known)) < (best or (limit + 1, 1, "")):
            best = key
    return None if best is None else best[2]


def _corrected(tokens: Sequence[str], unknown: Sequence[str], places: Sequence[str]) -> str:
    """The query with typos replaced and other unknown words (and places) dropped."""
    out: list[str] = []
    i = 0
    while i < len(tokens):
        two = " ".join(tokens[i : i + 2])
        n = 2 if two in places else 1
        word = tokens[i]
        if n == 2 or word in places or word in unknown:
            fixed = nearest_word(word) if word in unknown else None
            if fixed is None:
                while out and out[-1] in _LEADING:
                    out.pop()
            else:
                out.append(fixed)
        else:
            out.append(word)
        i += n
    return " ".join(out)


def refusal(
    text: str,
    tokens: Sequence[str],
    unknown: Sequence[str],
    places: Sequence[str],
    fallback: str,
    parses: Callable[[str], bool],
    understood: str,
) -> str:
    """The one-line refusal: the words not read, a place note, a question that parses (the
    corrected query, else ``fallback``) and what the grammar understands."""
    quoted = ", ".join(f'"{w}"' for w in dict.fromkeys([*unknown, *places]))
    note = ""
    if places:
        named = ", ".join(f'"{p}"' for p in dict.fromkeys(places))
        note = f" ({named}: hiper keeps no named places; ask near an object or 'here' instead)"
    suggestion = _corrected(tokens, unknown, places)
    if not suggestion or not parses(suggestion):
        suggestion = fallback
    return (f'cannot read {quoted} in "{text}"{note}; did you mean "{suggestion}"? '
            f"hiper understands: {understood}")
