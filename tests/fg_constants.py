"""Setting the foreground's named constants for one test (they were options; now fixed values
beside the code that reads them, so a test that shows a rule at work sets them by monkeypatch)."""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import fields
from typing import Any

import pytest

import hiper_cli.perceive.foreground as foreground
from hiper_cli.perceive.foreground.config import ForegroundConfig


def _owner(name: str) -> Any:
    """The foreground module that defines the constant ``name`` (not one that imports it)."""
    for info in pkgutil.iter_modules(foreground.__path__):
        module = importlib.import_module(f"{foreground.__name__}.{info.name}")
        if name in vars(module) and name in module.__annotations__:
            return module
    raise AttributeError(f"no foreground module defines {name}")


def patched(monkeypatch: pytest.MonkeyPatch, **options: Any) -> ForegroundConfig:
    """A ``ForegroundConfig`` of the options that are its fields, with the other names set as
    named constants for this test (``velocity_decay_s`` sets ``VELOCITY_DECAY_S``)."""
    known = {f.name for f in fields(ForegroundConfig)}
    set_constants(monkeypatch, **{k: v for k, v in options.items() if k not in known})
    return ForegroundConfig(**{k: v for k, v in options.items() if k in known})


def set_constants(monkeypatch: pytest.MonkeyPatch, **constants: Any) -> None:
    """Set the named constants for this test, in the module that defines each and in every
    foreground module that imported it."""
    for name, value in constants.items():
        const = name.upper()
        owner = _owner(const)
        monkeypatch.setattr(owner, const, value)
        for info in pkgutil.iter_modules(foreground.__path__):
            module = importlib.import_module(f"{foreground.__name__}.{info.name}")
            if module is not owner and const in vars(module):
                monkeypatch.setattr(module, const, value)


@contextmanager
def constants(**options: Any) -> Iterator[dict[str, Any]]:
    """Within the block, the names among ``options`` that are no ``ForegroundConfig`` field are
    set as named constants; yields the others (the options to pass on)."""
    known = {f.name for f in fields(ForegroundConfig)}
    with pytest.MonkeyPatch.context() as monkeypatch:
        set_constants(monkeypatch, **{k: v for k, v in options.items() if k not in known})
        yield {k: v for k, v in options.items() if k in known}
