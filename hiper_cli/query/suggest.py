"""The refusal of a query the grammar cannot read: it quotes every word not understood, says
when one is a place name (hiper keeps no named places), and offers a question that parses.

A word is replaced by a known one only when the two are near relative to the word's length:
one edit for 6-7 letters, two from 8, a letter missing, doubled or swapped with its neighbour
for 4-5, only a swap for 3 ("chiars" -> "chairs", "teh" -> "the"), never "count" -> "computer",
"open" -> "oven" or "kitchen" -> "kite"; place names are never replaced at all. Other unknown
words are dropped with the prepositions that led to them ("cups in the kitchen" -> "cups").
The result is offered when it parses and still asks about something (a class, a place, a
change); else a question built from what was understood ("how many chairs").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import cache

from hiper_cli.query.phrases import keywords
from hiper_cli.query.vocabulary import PLACE_WORDS, class_words

__all__ = ["edit_distance", "max_edits", "nearest_word", "refusal"]

_TRAILING = frozenset(["is", "are", "was", "were", "there", "the", "a", "an", "my", "of", "and", "please",
                       "by", "to", "with", "in", "at", "on"])
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
    """How many edits a typo of ``word`` may hold: none below 3 letters, one up to 7, then two."""
    return 0 if len(word) < 3 else 1 if len(word) < 8 else 2


def _near_enough(word: str, known: str, d: int) -> bool:
    """A short word's typo is a swap of neighbours (3 letters) or a letter missing, doubled or
    swapped (4-5 letters), not another letter: "open" is no typo of "oven"."""
    if d == 0 or d > max_edits(word):
        return False
    if len(word) == 3:
        return sorted(word) == sorted(known)
    if len(word) <= 5 and len(word) == len(known):
        return sorted(word) == sorted(known)
    return True


@cache
def _vocabulary() -> tuple[str, ...]:
    words = keywords()
    for phrase in class_words():
        words.update(phrase.split())
    return tuple(sorted(w for w in words if w.isalpha() and w not in PLACE_WORDS))


def nearest_word(word: str, vocabulary: Sequence[str] | None = None) -> str | None:
    """The known word within ``max_edits`` of ``word`` (fewest edits, then the same first
    letter, then alphabetical), or None."""
    limit = max_edits(word)
    if limit == 0:
        return None
    best: tuple[int, bool, bool, int, str] | None = None
    for known in vocabulary if vocabulary is not None else _vocabulary():
        if abs(len(known) - len(word)) > limit:
            continue
        if not _near_enough(word, known, edit_distance(word, known)):
            continue
        d = edit_distance(word, known)
        key = (d, not known.startswith(word), known[0] != word[0], -_common_prefix(word, known), known)
        if best is None or key < best:
            best = key
    return None if best is None else best[-1]


def _common_prefix(a: str, b: str) -> int:
    n = 0
    while n < min(len(a), len(b)) and a[n] == b[n]:
        n += 1
    return n


def _corrected(tokens: Sequence[str], unknown: Sequence[str], places: Sequence[str]) -> str:
    """The query with typos replaced and other unknown words (and places) dropped."""
    out: list[str] = []
    i = 0
    while i < len(tokens):
        two = " ".join(tokens[i : i + 2])
        n = 2 if two in places else 1
        word = tokens[i]
        fixed = nearest_word(word) if word in unknown and word not in _vocabulary() else word
        if n == 2 or word in places or fixed is None:  # drop it and the words leading to it
            while out and out[-1] in _LEADING:
                out.pop()
        else:
            out.append(fixed)
        i += n
    while out and out[-1] in _TRAILING:  # "how many chairs are"
        out.pop()
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
    # Known words left unread because of a neighbour ("many" after "hwo") are not quoted.
    strange = [w for w in unknown if w not in _vocabulary()] or list(unknown)
    quoted = ", ".join(f'"{w}"' for w in dict.fromkeys([*strange, *places]))
    note = ""
    if places:
        named = ", ".join(f'"{p}"' for p in dict.fromkeys(places))
        note = f" ({named}: hiper keeps no named places; ask near an object or 'here' instead)"
    suggestion = _corrected(tokens, unknown, places)
    if not suggestion or not parses(suggestion):
        suggestion = fallback
    return (f'cannot read {quoted} in "{text}"{note}; did you mean "{suggestion}"? '
            f"hiper understands: {understood}")
