"""The ``vcage`` command line. Only this module configures output and exits."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.table import Table

from vcage.config import Randomization
from vcage.errors import ConfigError, VcageError

if TYPE_CHECKING:
    from vcage.tasks.layout import SceneConfig

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="vcage: verified robot manipulation datasets in MuJoCo.")
console = Console()

DEMO_TASKS = ("stack_blocks_two", "place_mouse_pad", "click_bell", "place_bread_basket")
DEMO_CAMERAS = ("front", "overview", "top", "panda/wrist")
DEMO_CLUTTER = 4  # distractors placed around each demo task's objects


def _fail(exc: VcageError) -> None:
    console.print(f"[red]error:[/red] {exc}")
    raise typer.Exit(2)


@app.command("tasks")
def list_tasks() -> None:
    """List the atomic tasks with an example instruction."""
    import numpy as np

    from vcage.tasks.base import TASKS
    from vcage.tasks.runner import make_task

    make_task("stack_blocks_two")  # loads the library
    table = Table("task", "example instruction")
    for name in TASKS.names():
        task = TASKS.get(name)()
        task.build(np.random.default_rng(0), Randomization.off())
        table.add_row(name, task.instruction())
    console.print(table)
    from vcage.planning.goals import GOALS

    goals = Table("long-horizon goal", "subtasks", "example instructions")
    for g in GOALS:
        goals.add_row(g.name, str(len(g.subtasks)), "; ".join(g.phrasings[:2]))
    console.print(goals)
    console.print("explicit sequences also work, e.g. 'put the mouse on the mouse pad, then press the bell'")


@app.command("plan")
def plan_cmd(instruction: str = typer.Argument(..., help="what the robot should do"),
             planner: str = typer.Option("offline", help="offline, or llm (VCAGE_LLM_* env vars)")) -> None:
    """Ground INSTRUCTION into a plan and print it (nothing is simulated)."""
    from vcage.planning import make_planner

    try:
        result = make_planner(planner).plan(instruction)
    except VcageError as exc:
        _fail(exc)
        return
    console.print(result.summary(), markup=False, highlight=False)


@app.command("generate")
def generate_cmd(
        instruction: str = typer.Argument(..., help="e.g. 'get ready for work'"),
        episodes: int = typer.Option(3, min=1, help="accepted episodes to produce"),
        out: Path = typer.Option(Path("out/dataset"), help="dataset directory (LeRobot v3 layout)"),
        mode: str = typer.Option("vcage", help="vcage, or vanilla (naive placement, no critic)"),
        planner: str = typer.Option("offline", help="offline or llm"),
        critic: str = typer.Option("image", help="critic that verifies each subtask: image "
                                   "(offline), vlm (VCAGE_VLM_* env vars), oracle"),
        placement: str = typer.Option("context", help="context, naive or rejection"),
        clutter: int = typer.Option(4, min=0, help="distractors per scene"),
        seed: int = typer.Option(0), max_attempts: int = typer.Option(10, min=1),
        cameras: str = typer.Option("front,panda/wrist", help="comma-separated cameras to record"),
        size: int = typer.Option(128, help="video width and height (even)"),
        workers: int = typer.Option(1, min=1, help="episodes attempted at once (one core each); the "
                                    "dataset is the same for any number"),
        executor: str = typer.Option("local", help="local (this machine: processes) or ray"),
        address: str = typer.Option(None, help="with --executor ray: a running cluster's address "
                                    "(e.g. auto); default: start Ray locally")) -> None:
    """Generate a verified dataset for INSTRUCTION; prints the funnel and writes stats.json."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from vcage.pipeline.config import GenerateConfig
    from vcage.pipeline.generate import generate

    try:
        cfg = GenerateConfig(mode=mode, planner=planner, critic=critic, placement=placement,
                             clutter=clutter, seed=seed, max_attempts=max_attempts,
                             cameras=tuple(c.strip() for c in cameras.split(",") if c.strip()),
                             size=(size, size))
        with Progress(TextColumn("{task.description}"), BarColumn(),
                      TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn(),
                      console=console) as bar:
            job = bar.add_task("episodes", total=episodes)

            def update(f: object) -> None:
                from vcage.pipeline.generate import Funnel

                assert isinstance(f, Funnel)
                bar.update(job, completed=f.accepted + f.given_up,
                           description=f"episodes (attempts {f.attempts}, accepted {f.accepted})")

            funnel = generate(instruction, episodes, out, cfg, progress=update, workers=workers,
                              executor=executor, address=address)
    except VcageError as exc:
        _fail(exc)
        return
    _print_funnel(funnel.to_dict(), out)


def _print_funnel(stats: dict, out: Path) -> None:
    table = Table("stage", "attempts")
    for stage, n in sorted(stats["stages"].items(), key=lambda kv: -kv[1]):
        table.add_row(stage, str(n))
    console.print(table)
    if stats["rejections_by_reason"]:
        reasons = Table("rejected at: reason", "attempts")
        for reason, n in stats["rejections_by_reason"].items():
            reasons.add_row(reason, str(n))
        console.print(reasons)
    ratio = stats["total_over_physics_and_render"]
    timing = f"; total / (physics + render) = {ratio:.2f}" if ratio else ""
    console.print(
        f"accepted {stats['accepted']}/{stats['episodes_requested']} episodes in {stats['attempts']} "
        f"attempts ({stats['given_up']} given up); label noise (oracle audit of accepted): "
        f"{stats['label_noise']:.1%}; {stats['wall_seconds']:.1f} s wall, "
        f"{stats['episodes_per_hour']:.0f} episodes/hour on {stats['workers']} worker(s) "
        f"({stats['episodes_per_core_hour']:.0f} per core-hour){timing}")
    console.print(f"dataset and stats.json in {out}/")


@app.command("inspect")
def inspect_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Summarise a dataset: episodes, frames, tasks, cameras and per-episode outcomes."""
    from vcage.data import DatasetReader

    try:
        reader = DatasetReader(path)
        rows = [(i, reader.episode_meta(i), reader.extras(i)) for i in range(reader.num_episodes)]
    except VcageError as exc:
        _fail(exc)
        return
    console.print(f"{path}: {reader.num_episodes} episodes, {reader.total_frames} frames at "
                  f"{reader.fps} fps; "
                  f"cameras {', '.join(f'{k} {w}x{h}' for k, (h, w) in reader.cameras.items())}")
    table = Table("episode", "frames", "seed", "subtasks", "oracle", "task")
    for i, meta, extras in rows:
        table.add_row(str(i), str(meta.get("length")), str(extras.get("seed")),
                      str(len(extras.get("subtasks", []))),
                      "ok" if extras.get("oracle_success") else "[red]failed[/red]",
                      str(meta.get("tasks", [""])[0]))
    console.print(table)


@app.command("audit")
def audit_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Label noise of a dataset and the critic's agreement with the oracle, from the attempt log."""
    from vcage.data import DatasetReader
    from vcage.pipeline.audit import audit

    try:
        DatasetReader(path)
        report = audit(path)
    except VcageError as exc:
        _fail(exc)
        return
    console.print(report.summary())


@app.command("export")
def export_cmd(path: Path = typer.Argument(..., help="a dataset directory"),
               out: Path = typer.Argument(..., help="the file to write, e.g. demos.hdf5"),
               format: str = typer.Option("robomimic", help="robomimic (HDF5)"),
               valid: float = typer.Option(0.1, help="share of episodes in mask/valid"),
               overwrite: bool = typer.Option(False, help="replace OUT if it exists")) -> None:
    """Export a dataset for policy learning: robomimic's HDF5 layout."""
    if format != "robomimic":
        _fail(ConfigError(f"unknown export format {format!r}; valid: robomimic"))
    from vcage.data.robomimic import export_robomimic

    try:
        summary = export_robomimic(path, out, valid_fraction=valid, overwrite=overwrite)
    except VcageError as exc:
        _fail(exc)
        return
    console.print(f"wrote {summary.path}: {summary.demos} demos ({summary.train} train, {summary.valid} "
                  f"valid), {summary.frames} frames; obs keys {', '.join(summary.obs_keys)}")


@app.command("catalog")
def list_catalog(category: str = typer.Option(None, help="only this category"),
                 tag: str = typer.Option(None, help="only objects with this tag")) -> None:
    """List the annotated object catalog."""
    from vcage.assets.catalog import CATALOG

    try:
        objs = CATALOG.by_category(category) if category else CATALOG.all()
    except VcageError as exc:
        _fail(exc)
        return
    if tag:
        objs = [o for o in objs if tag in o.tags]
    table = Table("name", "category", "size (cm)", "grasps", "placements", "functional", "description")
    for o in objs:
        table.add_row(o.name, o.category, " x ".join(f"{s * 100:.1f}" for s in o.size),
                      str(len(o.grasps)), str(len(o.placements)), str(len(o.functional_points)),
                      o.description)
    console.print(table)
    console.print(f"{len(objs)} object types")


@app.command("scene")
def scene(objects: int = typer.Option(20, min=0, help="catalog objects to place as clutter"),
          method: str = typer.Option("context", help="placement method: context, naive, rejection"),
          seed: int = typer.Option(0), out: Path = typer.Option(Path("out/scene")),
          width: int = typer.Option(640), height: int = typer.Option(480)) -> None:
    """Instantiate a cluttered table, check it in physics, and render it from the top."""
    import numpy as np
    from PIL import Image

    from vcage.scene.compose import compose
    from vcage.scene.layout import Distractors, LayoutSpec
    from vcage.scene.placement import place
    from vcage.scene.stability import check_stability
    from vcage.sim.render import Renderer
    from vcage.skills.reach import reach_map

    try:
        result = place(LayoutSpec(distractors=Distractors(objects)), np.random.default_rng(seed),
                       method, reach=reach_map())
        world = compose(result.scene).make_world()
        report = check_stability(world)
    except VcageError as exc:
        _fail(exc)
        return
    out.mkdir(parents=True, exist_ok=True)
    with Renderer(world, width, height) as renderer:
        Image.fromarray(renderer.rgb("top")).save(out / f"{method}_{objects}_seed{seed}.png")
    secs = np.asarray(result.stats.seconds) * 1000
    (out / f"{method}_{objects}_seed{seed}.json").write_text(json.dumps(
        {"scene": result.scene.to_dict(), "stability": report.reason(),
         "ms_per_object": secs.tolist(), "backtracks": result.stats.backtracks}, indent=2))
    verdict = "[green]valid[/green]" if report.ok else f"[red]invalid[/red]: {report.reason()}"
    console.print(f"{method}: placed {result.stats.placed} objects in {secs.sum():.1f} ms "
                  f"(median {np.median(secs) if secs.size else 0:.2f} ms/object, "
                  f"{result.stats.backtracks} backtracks, {result.stats.coverage:.0%} of the table "
                  f"covered); after settling: {verdict}")
    console.print(f"image and scene spec in {out}/")


@app.command("run")
def run(task: str = typer.Argument(..., help="atomic task name (see `vcage tasks`)"),
        episodes: int = typer.Option(1, min=1), seed: int = typer.Option(0),
        randomize: bool = typer.Option(True, help="domain randomisation on/off"),
        out: Path = typer.Option(Path("out/run"), help="where images and results go"),
        placement: str = typer.Option("context", help="placement method: context, naive, rejection"),
        clutter: int = typer.Option(0, min=0, help="distractors added around the task's objects"),
        width: int = typer.Option(320), height: int = typer.Option(240)) -> None:
    """Run the scripted expert of TASK and save before/after images of every episode."""
    try:
        rows = _run_tasks([task] * episodes, [seed + i for i in range(episodes)], randomize, out,
                          width, height, _scene_config(placement, clutter))
    except VcageError as exc:
        _fail(exc)
        return
    _print_results(rows, out)


@app.command("demo")
def demo(out: Path = typer.Option(Path("out/demo")), seed: int = typer.Option(0),
         clutter: int = typer.Option(DEMO_CLUTTER, min=0, help="distractors per scene"),
         width: int = typer.Option(320), height: int = typer.Option(240)) -> None:
    """Run a few atomic tasks in cluttered scenes with their scripted experts; write images."""
    try:
        rows = _run_tasks(list(DEMO_TASKS), [seed] * len(DEMO_TASKS), True, out, width, height,
                          _scene_config("context", clutter))
    except VcageError as exc:
        _fail(exc)
        return
    _print_results(rows, out)


def _scene_config(placement: str, clutter: int) -> SceneConfig:
    from vcage.tasks.layout import SceneConfig

    return SceneConfig(placement, clutter)


def _run_tasks(tasks: list[str], seeds: list[int], randomize: bool, out: Path, width: int,
               height: int, scene: SceneConfig) -> list[dict]:
    from PIL import Image

    from vcage.sim.render import Renderer
    from vcage.tasks.runner import run_episode

    out.mkdir(parents=True, exist_ok=True)
    rand = Randomization() if randomize else Randomization.off()
    rows = []
    for task, seed in zip(tasks, seeds, strict=True):
        t0 = time.perf_counter()
        result = run_episode(task, seed, rand, scene=scene)
        elapsed = time.perf_counter() - t0
        world = result.world
        final = world.get_state()
        with Renderer(world, width, height) as renderer:
            after = [renderer.rgb(c) for c in DEMO_CAMERAS]
            world.set_state(result.initial_state)
            before = [renderer.rgb(c) for c in DEMO_CAMERAS]
        world.set_state(final)
        import numpy as np

        sheet = np.concatenate([np.concatenate(before, 1), np.concatenate(after, 1)], 0)
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


def main() -> None:
    app()


if __name__ == "__main__":
    main()
