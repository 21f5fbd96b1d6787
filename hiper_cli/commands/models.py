"""``hiper models list|fetch|add``: the detector models hiper knows and getting them here."""

from __future__ import annotations

from hiper_cli.cmdline import JSON_OPTION, HiperTyper, group
from hiper_cli.cmdline import models as o
from hiper_cli.render import download_bar, emit
from hiper_cli.render.models import show_added, show_fetched, show_models

__all__ = ["models_app", "register"]

models_app = group("models", o.HELP)


@models_app.command("list")
def list_command(directory: o.DirOption = None, as_json: bool = JSON_OPTION) -> None:
    """The known detectors: layout, input size, licence, COCO mAP, sha256 and where each is here.

    Example: hiper models list
    """
    from hiper_cli.perceive.detect.install import list_models

    emit(list_models(directory), as_json, show_models)


@models_app.command("fetch")
def fetch_command(name: o.ModelName, directory: o.DirOption = None, from_url: o.FromUrl = None,
                  trust_unverified: o.TrustUnverified = False, timeout_s: o.TimeoutS = 30.0,
                  as_json: bool = JSON_OPTION) -> None:
    """Download a model from its official release URL (HTTPS), resumable, verified by sha256.

    The file is written as NAME.onnx.part and renamed to NAME.onnx only after the sha256 matches;
    an interrupted download resumes where it stopped.

    Example: hiper models fetch yolox
    """
    from hiper_cli.perceive.detect.install import fetch_named_model

    with download_bar() as bar:
        data = fetch_named_model(name, directory, url=from_url, allow_unverified=trust_unverified,
                                 on_start=bar.start, progress=bar.update, timeout_s=timeout_s)
    emit(data, as_json, show_fetched)


@models_app.command("add")
def add_command(path: o.ModelFile, name: o.Name = None, labels: o.Labels = None,
                directory: o.DirOption = None, as_json: bool = JSON_OPTION) -> None:
    """Copy a model file into the models folder, so that --detector NAME finds it.

    A known model must have its known sha256; any model must be in a layout hiper reads.

    Example: hiper models add ~/Downloads/yolox_nano.onnx
    """
    from hiper_cli.perceive.detect.install import add_model_file

    emit(add_model_file(path, name, labels, directory), as_json, show_added)


def register(app: HiperTyper) -> None:
    app.add_typer(models_app, name="models")
