"""Code-generation evaluation (the appendix): n programs per task, each scored on S seeds.

For each evaluation task (a candidate subtask in its scene) a model is asked ``n`` times for a
program with the prompt of :mod:`vcage.subtasks.codegen` (no repair loop: raw samples are scored).
Each program runs S trials in the sandbox and MuJoCo (:func:`~vcage.subtasks.trial.run_trial`, all
programs of a task on the same S seeds); its SR is successes / S. Per task: **Avg SR** (mean over the
n programs), **Top-3 SR** (mean of the 3 best) and **pass@k**, the unbiased estimator over the n
samples, counting a program correct when it would be accepted (SR > 0.5). The offline reference is
the template written as a program (:meth:`Candidate.program_text`), n times.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

from vcage.backends import ChatBackend
from vcage.critics.base import Critic
from vcage.errors import EmptyReplyError
from vcage.scene.spec import SceneSpec
from vcage.subtasks.candidates import Candidate
from vcage.subtasks.codegen import extract_program, prompt, prompt_hash
from vcage.subtasks.stats import accepted, pass_at_k, top_k_mean
from vcage.subtasks.trial import TrialConfig, run_trial

KS = (1, 3, 5)


@dataclass(frozen=True)
class TaskScore:
    task: str
    rates: tuple[float, ...]  # SR of each program
    seeds: int
    failures: dict[str, int] = field(default_factory=dict)  # failed trials by class

    @property
    def avg_sr(self) -> float:
        return sum(self.rates) / len(self.rates) if self.rates else 0.0

    @property
    def top3_sr(self) -> float:
        return top_k_mean(self.rates, 3)

    @property
    def correct(self) -> int:
        return sum(accepted(round(r * self.seeds), self.seeds) for r in self.rates)

    def pass_at(self, k: int) -> float | None:
        return pass_at_k(len(self.rates), self.correct, k) if k <= len(self.rates) else None


def sample_programs(backend: ChatBackend, cand: Candidate, spec: SceneSpec, n: int) -> list[str]:
    """``n`` programs the model writes for ``cand`` (a reply without text counts as an empty program)."""
    messages = prompt(cand, spec)
    out = []
    for _ in range(n):
        try:
            out.append(extract_program(backend.chat(messages)))
        except EmptyReplyError:
            out.append("\n")
    return out


def score(cand: Candidate, spec: SceneSpec, programs: Sequence[str], seeds: int, critic: Critic | None = None,
          cfg: TrialConfig = TrialConfig(), model: str = "reference") -> TaskScore:
    """Each program's SR over the same ``seeds`` trials of ``cand``'s scene."""
    rates, failures = [], Counter[str]()
    digest = prompt_hash(prompt(cand, spec))
    for code in programs:
        program = cand.with_program(code, model, digest)
        trials = [run_trial(program, spec, k, critic, cfg, identity=cand.id) for k in range(seeds)]
        rates.append(sum(t.success for t in trials) / seeds)
        failures.update(t.failure_class for t in trials if t.failure_class)
    return TaskScore(cand.description, tuple(rates), seeds, dict(failures))


def table(rows: Sequence[tuple[str, TaskScore]], ks: Sequence[int] = KS) -> str:
    """The appendix's table: per source and task, n, S, Avg SR, Top-3 SR and pass@k."""
    head = ["source", "task", "n", "S", "Avg SR", "Top-3 SR", *(f"pass@{k}" for k in ks)]
    lines = [" | ".join(head), " | ".join("---" for _ in head)]
    for source, s in rows:
        passes = [s.pass_at(k) for k in ks]
        lines.append(" | ".join([source, s.task, str(len(s.rates)), str(s.seeds), f"{s.avg_sr:.3f}",
                                 f"{s.top3_sr:.3f}", *("-" if p is None else f"{p:.3f}" for p in passes)]))
    return "\n".join(lines)
