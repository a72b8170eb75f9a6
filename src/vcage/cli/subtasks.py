"""``vcage subtasks verify|list|show|chain|export-sft``: candidate subtasks verified in simulation, in a
SQLite database, long-horizon chains composed from them, and their programs as fine-tuning data."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.table import Column, Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors

subtasks_app = typer.Typer(no_args_is_help=True, help="Verify candidate subtasks of scenes in simulation "
                           "(accept iff SR > 0.5) and browse the subtask database.")
app.add_typer(subtasks_app, name="subtasks")

DB = typer.Option(Path("out/subtasks.db"), "--db", help="the subtask database (SQLite, created if missing)")


@subtasks_app.command("verify")
@cli_errors
def verify(scenes: list[str] = typer.Argument(..., help="task:<name>[@seed], a task name, goal:<name>[@seed] "
                                             "(a library goal's scene), or a scene_spec.json (or its "
                                             "directory) from `vcage synthesize`"),
           db: Path = DB, trials: int = typer.Option(10, min=1, help="trials per candidate"),
           critic: str = typer.Option("image", help="critic that must accept each trial: image, oracle, "
                                      "vlm, or none (oracle predicates only)"),
           llm: bool = typer.Option(False, help="ask the model of VCAGE_LLM_* for a program per candidate "
                                    "(run in the sandbox) instead of the template"),
           only: str = typer.Option("", help="verify only candidates whose template is this "
                                    "(put_on, put_in, press)"),
           propose: int = typer.Option(0, min=0, help="also ask the model of VCAGE_LLM_* to propose up to "
                                       "this many subtasks of its own per scene"),
           busy_timeout: float = typer.Option(30.0, help="seconds to wait for another writer")) -> None:
    """Enumerate each scene's candidate subtasks, run each TRIALS times, store the verdicts."""
    from vcage.errors import ConfigError
    from vcage.pipeline.scene_refs import resolve
    from vcage.subtasks.candidates import candidates
    from vcage.subtasks.codegen import ProgramWriter
    from vcage.subtasks.proposals import SubtaskProposer
    from vcage.subtasks.store import SubtaskStore
    from vcage.subtasks.trial import TrialConfig
    from vcage.subtasks.verify import Funnel, verify_all

    if only not in ("", "put_on", "put_in", "press"):
        raise ConfigError(f"--only {only!r}; valid: put_on, put_in, press")
    cfg = TrialConfig(trials=trials)
    resolved = [resolve(ref) for ref in scenes]  # every scene is checked before anything is written
    judge = _critic(critic)
    backend = _backend() if llm or propose else None
    writer = ProgramWriter(backend) if llm and backend is not None else None
    proposer = SubtaskProposer(backend, propose) if propose and backend is not None else None
    total = Funnel()
    db.parent.mkdir(parents=True, exist_ok=True)
    with SubtaskStore(db, busy_timeout=busy_timeout) as store:
        for scene, spec in resolved:
            known = candidates(scene.id, spec)
            cands = [c for c in known if not only or c.template == only]
            if proposer is not None:
                extra, counts = proposer.propose(scene.id, spec, known)
                console.print(f"scene {scene.id}: the model proposed {counts.proposed} subtask(s) in "
                              f"{counts.replies} replies: {counts.valid} kept, {counts.duplicates} repeating "
                              f"known ones, {counts.invalid} still invalid", highlight=False)
                for problem in counts.problems:
                    console.print(f"  still invalid: {problem}", highlight=False, markup=False)
                cands += extra
            if writer is not None:
                cands = [writer.write(c, spec) for c in cands]
            console.print(f"scene {scene.id} ({scene.source}): {len(cands)} candidate(s)")
            total.add(verify_all(scene, spec, cands, store, judge, cfg, None if critic == "none" else critic,
                                 progress=_print_record))
    console.print("funnel: " + ", ".join(f"{k} {v}" for k, v in total.to_dict().items()))


@subtasks_app.command("list")
@cli_errors
def list_subtasks(db: Path = DB, status: str = typer.Option("", help="accepted or rejected"),
                  scene: str = typer.Option("", help="only this scene id")) -> None:
    """List the stored subtasks with their success rates."""
    from vcage.errors import ConfigError
    from vcage.subtasks.store import SubtaskStore

    if status not in ("", "accepted", "rejected"):
        raise ConfigError(f"status {status!r}; valid: accepted, rejected")
    with SubtaskStore(db, readonly=True) as store:
        rows = store.subtasks(status or None, scene or None)
    table = Table(Column("id", no_wrap=True), "scene", "status", "SR", "95% CI", "source", "subtask")
    for r in rows:
        table.add_row(r.id, r.scene_id, r.status, f"{r.successes}/{r.trials}",
                      f"[{r.ci_low:.2f}, {r.ci_high:.2f}]", r.source, r.description)
    console.print(table)


@subtasks_app.command("show")
@cli_errors
def show(subtask_id: str = typer.Argument(..., help="an id or a unique prefix of one"),
         db: Path = DB) -> None:
    """Print one subtask as JSON: its record, code and every trial."""
    from dataclasses import asdict

    from vcage.subtasks.store import SubtaskStore

    with SubtaskStore(db, readonly=True) as store:
        record, trials = store.get(subtask_id)
    console.print_json(json.dumps({**record.to_dict(), "trial_log": [asdict(t) for t in trials]}))


@subtasks_app.command("chain")
@cli_errors
def chain(db: Path = DB, length: int = typer.Option(3, min=1, max=12, help="subtasks in the chain"),
          scene: str = typer.Option("", help="only this scene id (default: a scene drawn with the seed)"),
          seed: int = typer.Option(0, min=0, help="seed that draws the scene and the chain")) -> None:
    """Compose a long-horizon chain of verified subtasks and print it as a plan (what `vcage generate
    --subtasks DB --chain LENGTH --seed SEED` runs)."""
    from vcage.subtasks.chains import compose
    from vcage.subtasks.store import SubtaskStore

    with SubtaskStore(db, readonly=True) as store:
        composed = compose(store, length, seed, scene or None)
    console.print(f"scene {composed.provenance.scene_id} ({composed.scene.source})", highlight=False)
    for r in composed.records:
        console.print(f"  {r.id}  SR {r.successes}/{r.trials}  {r.description}", highlight=False)
    console.print(composed.plan.summary(), highlight=False, markup=False)


@subtasks_app.command("export-sft")
@cli_errors
def export_sft(out: Path = typer.Argument(..., help="directory for train.jsonl, eval.jsonl, split.json"),
               db: Path = DB, eval_share: float = typer.Option(0.2, min=0.0, max=1.0,
                                                               help="share of tasks held out for evaluation"),
               seed: int = typer.Option(0, min=0, help="seed of the task split")) -> None:
    """Export the accepted programs as prompt-completion JSONL for fine-tuning, split by task."""
    from vcage.subtasks.sft import export_sft as export
    from vcage.subtasks.store import SubtaskStore

    with SubtaskStore(db, readonly=True) as store:
        counts = export(store, out, eval_share, seed)
    console.print(f"train: {counts.train} examples of {len(counts.train_tasks)} tasks; eval: {counts.eval} "
                  f"examples of {len(counts.eval_tasks)} tasks (no task in both); written to {out}/")


def _print_record(r) -> None:  # type: ignore[no-untyped-def]
    console.print(f"  {r.id}  {r.status:8}  {r.description}: {r.reason}", highlight=False)


def _critic(name: str):  # type: ignore[no-untyped-def]
    if name == "none":
        return None
    from vcage.critics.base import CriticConfig, make_critic
    from vcage.pipeline.config import GenerateConfig

    cfg = GenerateConfig(critic=CriticConfig(name=name)).resolved().critic
    assert cfg is not None
    critic = make_critic(cfg)
    critic.preflight()
    return critic


def _backend():  # type: ignore[no-untyped-def]
    from vcage.backends import BackendConfig, connect

    return connect(BackendConfig.from_env("VCAGE_LLM"))  # no model set: ConfigError
