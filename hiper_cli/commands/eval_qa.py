"""``hiper eval qa``: a question-answering benchmark from a log's ground truth (``hiper_cli.qa``)."""

from __future__ import annotations

from typing import Any

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.cmdline import eval as o
from hiper_cli.commands.eval import eval_app
from hiper_cli.render import console, emit, frame_progress, log_bars
from hiper_cli.render.qa import show_qa, show_qa_set


@eval_app.command("qa")
def qa(logs: o.QaLogs, kb: o.QaKb = None, detector: o.QaDetector = "auto", out_dir: o.QaOut = None,
       short_s: o.ShortS = 15.0, seed: o.QaSeed = 0, glimpse_s: o.GlimpseS = 0.5,
       as_json: Json = False) -> None:
    """NaVQA-style questions (yes/no, count, position, time, duration; short and long
    horizons) generated from the log's truth, asked through the query layer and scored
    (position error horizontal, 3-D beside it); questions about classes the detector cannot
    name are scored apart. The questions with their true answers are written as JSONL.

    Example: hiper eval qa out/house -o out/house_qa --json

    Example: hiper eval qa out/house_1 out/office_2 out/hospital_3 -o out/qa
    """
    from hiper_cli.qa import evaluate_qa, evaluate_qa_set

    options: dict[str, Any] = {"detector": detector, "short_s": short_s, "seed": seed, "glimpse_s": glimpse_s}
    if len(logs) == 1 and (kb is None or len(kb) == 1):
        with frame_progress("perceive", console(), enabled=not as_json and kb is None) as bar:
            report = evaluate_qa(logs[0], kb=kb[0] if kb else None, out_dir=out_dir,
                                 progress=None if bar is None else bar.update, **options)
        answers = kb[0] if kb else None
        emit(report.to_dict(), as_json, lambda out, data: show_qa(out, data, logs[0], answers, glimpse_s))
        return
    with log_bars(len(logs), enabled=not as_json and kb is None) as on_log:
        result = evaluate_qa_set(logs, kbs=kb, out_dir=out_dir, on_log=on_log, **options)
    emit(result.to_dict(), as_json, lambda out, data: show_qa_set(out, data, glimpse_s))


def register(app: HiperTyper) -> None:
    """Nothing to do: this module adds itself to ``hiper eval`` on import."""
