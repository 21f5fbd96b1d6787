"""The options of ``hiper models``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

__all__ = ["HELP", "DirOption", "FromUrl", "Labels", "ModelFile", "ModelName", "Name", "TimeoutS",
           "TrustUnverified"]

HELP = ("List, download and add the detector models (ONNX) that --detector uses.\n\n"
        "Example: hiper models fetch yolox")

DirOption = Annotated[Path | None, typer.Option(
    "--dir", help="Models folder (default: $HIPER_MODELS, else ~/.cache/hiper/models).")]
ModelName = Annotated[str, typer.Argument(help="Model name from 'hiper models list' (yolox = yolox_nano).")]
FromUrl = Annotated[str | None, typer.Option(
    "--from", help="Download from this mirror URL instead; still checked against the known sha256.")]
TrustUnverified = Annotated[bool, typer.Option(
    "--trust-unverified", help="Allow a model whose sha256 hiper does not know (prints the sha256).")]
TimeoutS = Annotated[float, typer.Option("--timeout-s", help="Network timeout in seconds.")]
ModelFile = Annotated[Path, typer.Argument(help="An ONNX detector file you already have.")]
Name = Annotated[str | None, typer.Option(
    "--name", help="Name to use with --detector (default: the file name without .onnx).")]
Labels = Annotated[Path | None, typer.Option(
    "--labels", help="Class names, one a line, when the model's metadata has none.")]
