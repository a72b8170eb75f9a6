"""Simulation-based verification: N trials per candidate, accept iff SR > 0.5, into the database.

Each candidate runs ``TrialConfig.trials`` trials (default 10) on seeds derived from its identity
(:func:`~vcage.subtasks.trial.trial_seed`), so a rerun repeats every trial exactly. Its success
rate SR = successes / trials is stored with the 95 % Wilson interval, and it is **accepted iff
SR > 0.5** (the paper's strict inequality: 5 of 10 is rejected). A candidate whose code fails the
static checks is stored as rejected with no trials. Per run the funnel counts (as GenSim does):
``candidates``; ``valid`` (the code passed the static checks and its calls the argument checks in
the nominal scene); ``ran`` (at least one trial executed its skills in MuJoCo); ``succeeded`` (at
least one trial succeeded); ``accepted``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass

from vcage.critics.base import Critic
from vcage.errors import CodeRejectedError, SubtaskError
from vcage.provenance import software
from vcage.sandbox import check
from vcage.sandbox.protocol import QUERIES
from vcage.scene.spec import SceneSpec
from vcage.subtasks.calls import api, check_call
from vcage.subtasks.candidates import Candidate
from vcage.subtasks.records import ACCEPTED, REJECTED, SceneRecord, SubtaskRecord, TrialRecord
from vcage.subtasks.stats import accepted, wilson
from vcage.subtasks.store import SCHEMA_VERSION, SubtaskStore
from vcage.subtasks.trial import TrialConfig, run_trial, template_calls

# Failure classes that mean the skills never ran in MuJoCo.
NOT_RUN = frozenset({"scene", "rejected", "runtime_error", "blocked", "memory_limit", "cpu_limit", "timeout",
                     "crashed", "bad_output", "invalid_call", "already_holds"})


@dataclass
class Funnel:
    candidates: int = 0
    valid: int = 0
    ran: int = 0
    succeeded: int = 0
    accepted: int = 0

    def add(self, other: Funnel) -> None:
        for key, value in asdict(other).items():
            setattr(self, key, getattr(self, key) + value)

    def to_dict(self) -> dict[str, int]:
        return asdict(self)


def versions(critic: Critic | None) -> dict[str, str]:
    """The software that verified a subtask, the database schema and, where a critic judged, the
    critic's version (its rules' digest: a subtask verified under other rules can be told apart)."""
    out = {**software(), "schema": str(SCHEMA_VERSION)}
    if critic is not None:
        out["critic"] = critic.version()
    return out


def static_check(cand: Candidate, spec: SceneSpec) -> str | None:
    """Why ``cand``'s code cannot be run at all, or None: a program must pass the sandbox's
    allow-list; a template's calls must pass the argument checks in the nominal scene."""
    try:
        if cand.is_program:
            check(cand.code, [s.name for s in api()] + list(QUERIES))
        else:
            for call in template_calls(cand.code):
                check_call(call, spec)
    except (CodeRejectedError, SubtaskError) as exc:
        return str(exc)
    return None


def verify(cand: Candidate, spec: SceneSpec, critic: Critic | None, cfg: TrialConfig = TrialConfig(),
           critic_name: str | None = None) -> tuple[SubtaskRecord, list[TrialRecord], Funnel]:
    """Verify one candidate: its record, its trials and its share of the funnel."""
    funnel = Funnel(candidates=1)
    problem = static_check(cand, spec)
    trials: list[TrialRecord] = []
    if problem is None:
        funnel.valid = 1
        trials = [run_trial(cand, spec, k, critic, cfg) for k in range(cfg.trials)]
    wins = sum(t.success for t in trials)
    n = len(trials)
    ok = accepted(wins, n)
    funnel.ran = int(any(t.failure_class not in NOT_RUN for t in trials))
    funnel.succeeded = int(wins > 0)
    funnel.accepted = int(ok)
    lo, hi = wilson(wins, n)
    rate = wins / n if n else 0.0
    if problem is not None:
        reason = f"invalid: {problem}"
    else:
        failures = Counter(t.failure_class for t in trials if not t.success)
        listed = ", ".join(f"{k} {v}" for k, v in sorted(failures.items()))
        reason = (f"SR {rate:.2f} {'>' if ok else '<='} 0.5 ({wins}/{n})"
                  + (f"; failures: {listed}" if listed else ""))
    record = SubtaskRecord(
        id=cand.id, scene_id=cand.scene_id, skill=cand.skill, parameters=dict(cand.args),
        description=cand.description, predicates=tuple(str(p) for p in cand.predicates), code=cand.code,
        code_hash=cand.code_hash, source=cand.source, trials=n, successes=wins, success_rate=rate,
        ci_low=lo, ci_high=hi, status=ACCEPTED if ok else REJECTED, reason=reason, model=cand.model,
        prompt_hash=cand.prompt_hash, critic=critic_name, versions=versions(critic))
    return record, trials, funnel


def verify_all(scene: SceneRecord, spec: SceneSpec, cands: Sequence[Candidate], store: SubtaskStore | None,
               critic: Critic | None, cfg: TrialConfig = TrialConfig(), critic_name: str | None = None,
               progress: Callable[[SubtaskRecord], None] | None = None) -> Funnel:
    """Verify every candidate of one scene, storing each (with its trials) as soon as it is done."""
    total = Funnel()
    if store is not None:
        store.add_scene(scene)
    for cand in cands:
        record, trials, funnel = verify(cand, spec, critic, cfg, critic_name)
        if store is not None:
            store.put(record, trials)
        total.add(funnel)
        if progress is not None:
            progress(record)
    return total
