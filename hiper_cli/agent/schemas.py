"""JSON Schema fragments of the agent tools: strict inputs (``additionalProperties: false``)
and the shapes of their typed results (the query layer's ``to_dict`` forms)."""

from __future__ import annotations

from typing import Any

from hiper_cli.agent.times import TIME_HELP

__all__ = ["ERROR", "HIT", "TIME", "TIME_VALUE", "obj", "time_input"]

Schema = dict[str, Any]
NUMBER: Schema = {"type": "number"}
NULLABLE_NUMBER: Schema = {"type": ["number", "null"]}
STRING: Schema = {"type": "string"}


def obj(properties: Schema, required: tuple[str, ...] = (), *, strict: bool = True, **extra: Any) -> Schema:
    """An object schema; ``strict`` forbids properties it does not list."""
    out: Schema = {"type": "object", "properties": properties, "required": list(required)}
    if strict:
        out["additionalProperties"] = False
    return out | extra


def time_input(what: str) -> Schema:
    return {"type": ["number", "string"], "description": f"{what}: {TIME_HELP}."}


# "iso" is null for a log's own clock that is not wall-clock time (hiper_cli.clock)
TIME_VALUE: Schema = obj({"stamp_s": NUMBER, "iso": {"type": ["string", "null"]}, "ago": STRING},
                         ("stamp_s", "iso", "ago"))
TIME: Schema = {"anyOf": [TIME_VALUE, {"type": "null"}]}
VEC3: Schema = {"type": "array", "items": NUMBER, "minItems": 3, "maxItems": 3}
HIT: Schema = obj(
    {
        "uuid": STRING,
        "class": STRING,
        "layer": {"enum": ["background", "foreground"]},
        "position_m": VEC3,
        "box": obj({"center_m": VEC3, "extent_m": VEC3, "frame": STRING}, ("center_m", "extent_m")),
        "first_seen": TIME_VALUE,
        "last_seen": TIME_VALUE,
        "observation_count": {"type": "integer"},
        "confidence": NUMBER,
        "state": STRING,
        "speed_mps": NULLABLE_NUMBER,
        "distance_m": NUMBER,
        "support": {"anyOf": [obj({"class": STRING, "uuid": {"type": ["string", "null"]}}),
                              {"type": "null"}]},
        "evidence_uuids": {"type": "array", "items": STRING},
    },
    ("uuid", "class", "layer", "position_m", "first_seen", "last_seen", "distance_m"),
)
REFERENCE: Schema = obj(
    {"x_m": NUMBER, "y_m": NUMBER, "z_m": NUMBER, "yaw_rad": NUMBER, "stamp_s": NULLABLE_NUMBER,
     "source": STRING},
    ("x_m", "y_m", "z_m", "yaw_rad", "source"),
)
WINDOW: Schema = obj({"since": TIME, "until": TIME}, ("since", "until"))
POSE_INPUT: Schema = obj(
    {"x_m": NUMBER, "y_m": NUMBER, "z_m": NUMBER, "yaw_rad": NUMBER},
    ("x_m", "y_m"),
    description="Ask from this pose (map frame, m and rad; z default 1.2, yaw 0) instead of the "
    "robot's last pose.",
)
ERROR: Schema = obj(
    {"error": obj({"type": STRING, "message": STRING}, ("type", "message"))}, ("error",)
)
