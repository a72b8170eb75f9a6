"""``vcage run`` and ``vcage demo``: scripted experts of atomic tasks, with before/after images."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.config import Randomization

if TYPE_CHECKING:
    from vcage.scene.instantiate import SceneConfig

DEMO_TASKS = ("stack_blocks_two", "place_mouse_pad", "click_bell", "place_bread_basket")
DEMO_CAMERAS = ("front", "overview", "top", "panda/wrist")
DEMO_CLUTTER = 4  # distractors placed around each demo task's objects


@app.command("run")
@cli_errors
def run(task: str = typer.Argument(..., help="atomic task name (see `vcage tasks`)"),
        episodes: int = typer.Option(1, min=1), seed: int = typer.Option(0, min=0),
        randomize: bool = typer.Option(True, help="domain randomisation on/off"),
        out: Path = typer.Option(Path("out/run"), help="where images and results go"),
        placement: str = typer.Option("context", help="placement method: context, naive, rejection"),
        clutter: int = typer.Option(0, min=0, help="distractors added around the task's objects"),
        width: int = typer.Option(320), height: int = typer.Option(240)) -> None:
    """Run the scripted expert of TASK and save before/after images of every episode."""
    rows = _run_tasks([task] * episodes, [seed + i for i in range(episodes)], randomize, out,
                      width, height, _scene_config(placement, clutter))
    _print_results(rows, out)


@app.command("demo")
@cli_errors
def demo(out: Path = typer.Option(Path("out/demo")), seed: int = typer.Option(0, min=0),
         clutter: int = typer.Option(DEMO_CLUTTER, min=0, help="distractors per scene"),
         width: int = typer.Option(320), height: int = typer.Option(240)) -> None:
    """Run a few atomic tasks in cluttered scenes with their scripted experts; write images."""
    rows = _run_tasks(list(DEMO_TASKS), [seed] * len(DEMO_TASKS), True, out, width, height,
                      _scene_config("context", clutter))
    _print_results(rows, out)


def _scene_config(placement: str, clutter: int) -> SceneConfig:
    from vcage.scene.instantiate import SceneConfig

    return SceneConfig(placement, clutter)


def _run_tasks(tasks: list[str], seeds: list[int], randomize: bool, out: Path, width: int,
               height: int, scene: SceneConfig) -> list[dict]:
    from PIL import Image

    from vcage.sim.render import contact_sheet
    from vcage.tasks import run_episode

    out.mkdir(parents=True, exist_ok=True)
    rand = Randomization() if randomize else Randomization.off()
    rows = []
    for task, seed in zip(tasks, seeds, strict=True):
        t0 = time.perf_counter()
        result = run_episode(task, seed, rand, scene=scene)
        elapsed = time.perf_counter() - t0
        # top row: the initial state; bottom: the world as the episode left it
        sheet = contact_sheet(result.world, [result.initial_state, None], DEMO_CAMERAS, width, height)
        path = out / f"{task}_seed{seed}.png"
        Image.fromarray(sheet).save(path)
        rows.append({"task": task, "seed": seed, "success": result.success,
                     "instruction": result.instruction, "steps": len(result.recording),
                     "seconds": round(elapsed, 3), "image": str(path),
                     "skill_error": result.skill_error, "evaluation": result.info})
    (out / "results.json").write_text(json.dumps(rows, indent=2, default=str))
    return rows


def _print_results(rows: list[dict], out: Path) -> None:
    table = Table("task", "seed", "success", "steps", "time (s)", "instruction")
    for r in rows:
        ok = "[green]yes[/green]" if r["success"] else "[red]no[/red]"
        table.add_row(r["task"], str(r["seed"]), ok, str(r["steps"]), f"{r['seconds']:.2f}",
                      r["instruction"])
    console.print(table)
    console.print(f"images (top row: before, bottom: after; cameras {', '.join(DEMO_CAMERAS)}) "
                  f"and results.json in {out}/")
