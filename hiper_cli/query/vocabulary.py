"""The class words the query grammar understands: COCO names, hiper's own classes (walls,
floors, tables, ...), common synonyms and plurals, and the generic "objects"."""

from __future__ import annotations

from functools import cache

__all__ = [
    "ANY_FOREGROUND", "CLASS_NAMES", "PLACE_WORDS", "class_words", "counted", "plural", "resolve_class",
    "singular",
]

COCO = (
    "person",
    "bicycle",
    "car",
    "motorcycle",
    "airplane",
    "bus",
    "train",
    "truck",
    "boat",
    "traffic light",
    "fire hydrant",
    "stop sign",
    "parking meter",
    "bench",
    "bird",
    "cat",
    "dog",
    "horse",
    "sheep",
    "cow",
    "elephant",
    "bear",
    "zebra",
    "giraffe",
    "backpack",
    "umbrella",
    "handbag",
    "tie",
    "suitcase",
    "frisbee",
    "skis",
    "snowboard",
    "sports ball",
    "kite",
    "baseball bat",
    "baseball glove",
    "skateboard",
    "surfboard",
    "tennis racket",
    "bottle",
    "wine glass",
    "cup",
    "fork",
    "knife",
    "spoon",
    "bowl",
    "banana",
    "apple",
    "sandwich",
    "orange",
    "broccoli",
    "carrot",
    "hot dog",
    "pizza",
    "donut",
    "cake",
    "chair",
    "couch",
    "potted plant",
    "bed",
    "dining table",
    "toilet",
    "tv",
    "laptop",
    "mouse",
    "remote",
    "keyboard",
    "cell phone",
    "microwave",
    "oven",
    "toaster",
    "sink",
    "refrigerator",
    "book",
    "clock",
    "vase",
    "scissors",
    "teddy bear",
    "hair drier",
    "toothbrush",
)
HIPER_CLASSES = ("wall", "floor", "ceiling", "table", "door", "stairs", "shelf", "cart", "picture", "unknown")
CLASS_NAMES: tuple[str, ...] = COCO + HIPER_CLASSES
ANY_FOREGROUND = "objects"  # the generic word: every foreground class

SYNONYMS = {
    "mug": "cup",
    "glass": "cup",
    "sofa": "couch",
    "settee": "couch",
    "people": "person",
    "human": "person",
    "man": "person",
    "woman": "person",
    "men": "person",
    "women": "person",
    "child": "person",
    "children": "person",
    "kid": "person",
    "pedestrian": "person",
    "someone": "person",
    "somebody": "person",
    "anyone": "person",
    "anybody": "person",
    "television": "tv",
    "monitor": "tv",
    "screen": "tv",
    "plant": "potted plant",
    "houseplant": "potted plant",
    "flower": "potted plant",
    "desk": "table",
    "phone": "cell phone",
    "cellphone": "cell phone",
    "mobile": "cell phone",
    "smartphone": "cell phone",
    "trolley": "cart",
    "painting": "picture",
    "poster": "picture",
    "photo": "picture",
    "bookshelf": "shelf",
    "bookcase": "shelf",
    "armchair": "chair",
    "seat": "chair",
    "stool": "chair",
    "fridge": "refrigerator",
    "notebook": "laptop",
    "computer": "laptop",
    "staircase": "stairs",
    "stair": "stairs",
    "lady": "person",
    "everyone": "person",
    "everybody": "person",
    "guy": "person",
    "visitor": "person",
    "worker": "person",
    "customer": "person",
    "walker": "person",
    "telly": "tv",
    "tv screen": "tv",
    "flatscreen": "tv",
    "coffee table": "table",
    "side table": "table",
    "kitchen table": "table",
    "workbench": "table",
    "freezer": "refrigerator",
    "coffee cup": "cup",
    "coffee mug": "cup",
    "water bottle": "bottle",
    "office chair": "chair",
    "doorway": "door",
    "everything": ANY_FOREGROUND,
    "object": ANY_FOREGROUND,
    "objects": ANY_FOREGROUND,
    "thing": ANY_FOREGROUND,
    "item": ANY_FOREGROUND,
    "anything": ANY_FOREGROUND,
    "something": ANY_FOREGROUND,
    "stuff": ANY_FOREGROUND,
}
# Names of places (rooms, areas): a query naming one is refused with a note that hiper keeps no
# named places, never read as a class that happens to be spelled alike ("kitchen" is no "kite").
PLACE_WORDS = frozenset(
    [
        "kitchen", "bedroom", "bathroom", "office", "hallway", "hall", "corridor", "lobby", "garage",
        "lab", "laboratory", "warehouse", "aisle", "room", "rooms", "entrance", "entryway", "reception",
        "storeroom", "basement", "attic", "garden", "yard", "upstairs", "downstairs", "corner", "area",
        "zone", "house", "home", "building", "store", "shop", "bookstore", "living room",
        "dining room", "meeting room", "break room", "conference room", "loading dock", "back room",
        "stockroom", "canteen", "cafeteria", "lounge", "porch", "balcony", "place", "places",
    ]
)
IRREGULAR_PLURALS = {
    "people": "people",
    "men": "men",
    "women": "women",
    "children": "children",
    "knives": "knife",
    "mice": "mouse",
    "shelves": "shelf",
    "skis": "skis",
    "scissors": "scissors",
    "stairs": "stairs",
    "glasses": "glass",
    "dishes": "dish",
    "couches": "couch",
    "benches": "bench",
    "buses": "bus",
    "sandwiches": "sandwich",
    "boxes": "box",
    "ladies": "lady",
    "stuff": "stuff",
    "series": "series",
}


def singular(word: str) -> str:
    """The singular of an English noun, by the rules class names need."""
    if word in IRREGULAR_PLURALS:
        return IRREGULAR_PLURALS[word]
    if word.endswith("ies") and len(word) > 4:
        return word[:-3] + "y"
    if word.endswith(("ches", "shes", "sses", "xes")):
        return word[:-2]
    if word.endswith("s") and not word.endswith("ss") and len(word) > 2:
        return word[:-1]
    return word


def plural(name: str) -> str:
    """The plural of a class name ("cup" -> "cups", "person" -> "people", "potted plant" ->
    "potted plants"), the inverse of ``singular`` for the names it reads."""
    head, _, last = name.rpartition(" ")
    inverse = {v: k for k, v in IRREGULAR_PLURALS.items() if k != v} | {"person": "people", "sheep": "sheep"}
    if last in inverse:
        last = inverse[last]
    elif last.endswith("y") and last[-2:-1] not in ("a", "e", "o", "u") and len(last) > 2:
        last = last[:-1] + "ies"
    elif last.endswith(("s", "sh", "ch", "x")):
        last = last + "es" if singular(last + "es") == last else last
    else:
        last = last + "s"
    return f"{head} {last}".strip()


def counted(n: int, name: str) -> str:
    """``n`` things of class ``name`` in words: "1 cup", "3 cups", "0 people"."""
    return f"{n} {name if n == 1 else plural(name)}"


@cache
def class_words() -> dict[str, str]:
    """Every understood class phrase (singular and plural) -> a class name or "objects"."""
    words: dict[str, str] = {}
    for name in CLASS_NAMES:
        words[name] = name
    words.update(SYNONYMS)
    plurals = {}
    for phrase, target in words.items():
        head, _, last = phrase.rpartition(" ")
        for plural in (last + "s", last + "es", last[:-1] + "ies" if last.endswith("y") else ""):
            if plural and singular(plural) == last:
                plurals[(head + " " + plural).strip()] = target
    for plural, single in IRREGULAR_PLURALS.items():
        if single in words:
            plurals[plural] = words[single]
    return {**plurals, **words}


def resolve_class(words: str) -> str | None:
    """A class name (or "objects") for a phrase such as "mugs", "potted plants", "people"."""
    text = " ".join(words.lower().split())
    table = class_words()
    if text in table:
        return table[text]
    head, _, last = text.rpartition(" ")
    return table.get((head + " " + singular(last)).strip())
