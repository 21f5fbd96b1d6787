"""``hiper models list|fetch|add``: the detector models hiper knows and getting them here."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from hiper_cli.commands._common import JSON_OPTION
from hiper_cli.commands._render import console, group, print_json, safe_text

__all__ = ["models_app", "register"]

models_app = group(
    "models",
    "List, download and add the detector models (ONNX) that --detector uses.\n\n"
    "Example: hiper models fetch yolox",
)

DirOption = Annotated[
    Path | None,
    typer.Option("--dir", help="Models folder (default: $HIPER_MODELS, else ~/.cache/hiper/models)."),
]


@models_app.command("list")
def list_command(directory: DirOption = None, as_json: bool = JSON_OPTION) -> None:
    """The known detectors: layout, input size, licence, COCO mAP, sha256 and where each is here.

    Example: hiper models list
    """
    from hiper_cli.perceive.detect.catalog import catalog_rows, models_dir

    rows = catalog_rows(directory)
    if as_json:
        print_json({"models_dir": str(models_dir(directory)), "models": rows})
        return
    from rich.table import Table

    table = Table("name", "layout", "px", "MB", "licence", "mAP", "sha256", "where")
    home = str(Path.home())
    for r in rows:
        size = f"{r['size_bytes'] / 1e6:.1f}" if r["size_bytes"] else "?"
        sha = f"{r['sha256']}"[:8] if r["sha256"] else "unknown"
        coco = f"{r['coco_map']:.1f}" if r["coco_map"] is not None else "?"
        where = (
            str(r["path"]).replace(home, "~", 1) if r["path"] else ("-> fetch" if r["url"] else "-> export")
        )
        table.add_row(
            str(r["name"]),
            str(r["layout"]),
            f"{r['input_px'] or '?'}",
            size,
            safe_text(str(r["licence"])),
            coco,
            sha,
            safe_text(where),
        )
    out = console()
    out.print(table)
    out.print(
        f"models folder: {safe_text(str(models_dir(directory)))}; sha256 'unknown': not verified by "
        "hiper, fetched only with --trust-unverified"
    )


def _progress_bar() -> Any:
    from rich.console import Console
    from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TransferSpeedColumn

    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        DownloadColumn(),
        TransferSpeedColumn(),
        console=Console(stderr=True),
        transient=True,
    )


@models_app.command("fetch")
def fetch_command(
    name: Annotated[str, typer.Argument(help="Model name from 'hiper models list' (yolox = yolox_nano).")],
    directory: DirOption = None,
    from_url: Annotated[
        str | None,
        typer.Option(
            "--from", help="Download from this mirror URL instead; still checked against the known sha256."
        ),
    ] = None,
    trust_unverified: Annotated[
        bool,
        typer.Option(
            "--trust-unverified", help="Allow a model whose sha256 hiper does not know (prints the sha256)."
        ),
    ] = False,
    timeout_s: Annotated[float, typer.Option("--timeout-s", help="Network timeout in seconds.")] = 30.0,
    as_json: bool = JSON_OPTION,
) -> None:
    """Download a model from its official release URL (HTTPS), resumable, verified by sha256.

    The file is written as NAME.onnx.part and renamed to NAME.onnx only after the sha256 matches;
    an interrupted download resumes where it stopped.

    Example: hiper models fetch yolox
    """
    from hiper_cli.perceive.detect.catalog import entry, models_dir
    from hiper_cli.perceive.detect.fetch import fetch_model

    model = entry(name)
    with _progress_bar() as bar:
        task = bar.add_task(model.name, total=model.size_bytes)

        def progress(done: int, total: int | None) -> None:
            bar.update(task, completed=done, total=total)

        result = fetch_model(
            model,
            models_dir(directory),
            url=from_url,
            allow_unverified=trust_unverified,
            progress=progress,
            timeout_s=timeout_s,
        )
    data = {
        "name": model.name,
        "path": str(result.path),
        "sha256": result.sha256,
        "verified": result.verified,
        "downloaded_bytes": result.downloaded_bytes,
        "resumed_from": result.resumed_from,
        "url": from_url or model.url,
    }
    if as_json:
        print_json(data)
        return

    check = "verified" if result.verified else "NOT verified: no known sha256, check it yourself"
    resumed = f", resumed at {result.resumed_from} bytes" if result.resumed_from else ""
    got = (
        f"{result.downloaded_bytes} bytes downloaded{resumed}" if result.downloaded_bytes else "already here"
    )
    console().print(f"{model.name} -> {safe_text(str(result.path))} ({got}; sha256 {result.sha256} {check})")


@models_app.command("add")
def add_command(
    path: Annotated[Path, typer.Argument(help="An ONNX detector file you already have.")],
    name: Annotated[
        str | None,
        typer.Option("--name", help="Name to use with --detector (default: the file name without .onnx)."),
    ] = None,
    labels: Annotated[
        Path | None,
        typer.Option("--labels", help="Class names, one a line, when the model's metadata has none."),
    ] = None,
    directory: DirOption = None,
    as_json: bool = JSON_OPTION,
) -> None:
    """Copy a model file into the models folder, so that --detector NAME finds it.

    A known model must have its known sha256; any model must be in a layout hiper reads.

    Example: hiper models add ~/Downloads/yolox_nano.onnx
    """
    import shutil

    from hiper_cli.errors import ConfigError
    from hiper_cli.perceive.detect.catalog import CATALOG, ModelEntry, models_dir
    from hiper_cli.perceive.detect.fetch import add_model
    from hiper_cli.perceive.detect.onnx_model import OnnxDetector

    wanted = name or path.stem
    known = {e.name: e for e in CATALOG}
    model = known.get(wanted) or ModelEntry(wanted, "auto", 640, "(added)", None)
    if not path.is_file():
        raise ConfigError(f"{path}: no such file; pass the path of an .onnx model")
    detector = OnnxDetector(
        path, layout=None if model.layout == "auto" else model.layout, input_px=model.input_px, labels=labels
    )
    result = add_model(model, path, models_dir(directory))
    if labels is not None:
        shutil.copyfile(labels, result.path.with_name("labels.txt"))
    data = {
        "name": model.name,
        "path": str(result.path),
        "sha256": result.sha256,
        "verified": result.verified,
        "layout": detector.layout,
        "classes": len(detector.class_names),
    }
    if as_json:
        print_json(data)
        return

    console().print(
        f"{model.name} -> {safe_text(str(result.path))} ({detector.layout} layout, "
        f"{len(detector.class_names)} classes; use --detector {model.name})"
    )


def register(app: typer.Typer) -> None:
    app.add_typer(models_app, name="models")
