"""The configuration tree of a generation run, as data: stored with the dataset, compared on append.

Every option that changes the data is a field here, grouped by the stage it configures: planner
(with its model endpoint), scene, critic (with its endpoint and options), render, sim and
randomisation; the executor says where episodes run (it does not change the data). Model endpoints
left unset are read from the environment once, by :meth:`GenerateConfig.resolved`, and stored like
any other option; API keys are read from the environment when a request is made and never stored.
The Vanilla baseline is a preset, :meth:`GenerateConfig.vanilla`, not a mode that rewrites fields.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numpy as np

from vcage.backends import BackendConfig
from vcage.config import Randomization, RenderConfig, SimConfig, from_fields
from vcage.critics.base import CriticConfig
from vcage.critics.vlm import ENV_PREFIX as VLM_ENV_PREFIX
from vcage.errors import ConfigError
from vcage.planning import LLM_ENV_PREFIX, PlannerConfig
from vcage.scene.instantiate import SceneConfig
from vcage.skills.recovery import RecoveryConfig
from vcage.subtasks.chains import SubtaskChain
from vcage.synthesis.scene_file import SynthesisRequest, SynthesizedScene

SEED_LIMIT = 2**32  # seeds are unsigned 32-bit, as numpy's SeedSequence entropy
# how a backend is reached, not what it answers: not compared when appending to a dataset
TRANSPORT = ("api_key_env", "timeout", "max_retries", "backoff", "max_backoff", "breaker_failures",
             "preflight")


@dataclass(frozen=True)
class ExecutorConfig:
    """Where episodes run: ``local`` (this machine; more than one worker: processes) or ``ray``
    (``address``: a running cluster's; none: a local Ray instance), at most ``workers`` at once."""

    name: str = "local"
    workers: int = 1
    address: str | None = None

    def __post_init__(self) -> None:
        workers = self.workers
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ConfigError(f"workers must be a positive integer, got {workers!r}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ExecutorConfig:
        return from_fields(cls, data)


@dataclass(frozen=True)
class GenerateConfig:
    """A generation run. ``critic=None`` accepts every attempt that raised no exception (Vanilla).

    Each episode gets up to ``max_attempts`` attempts (scene re-samples) before it is given up;
    attempt seeds derive from ``seed`` (:meth:`episode_seed`).
    """

    seed: int = 0
    max_attempts: int = 10
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    scene: SceneConfig = field(default_factory=lambda: SceneConfig(clutter=4))
    critic: CriticConfig | None = field(default_factory=CriticConfig)
    render: RenderConfig = field(default_factory=RenderConfig)
    sim: SimConfig = field(default_factory=SimConfig)
    randomization: Randomization = field(default_factory=Randomization)
    executor: ExecutorConfig = field(default_factory=ExecutorConfig)
    # a synthesized scene (`vcage synthesize`) the episodes start from, with its provenance; None:
    # the plan's objects are placed afresh. Stored only when set, so runs without one are unchanged
    synthesized: SynthesizedScene | None = None
    # the verified subtasks (`vcage subtasks verify`) the plan was composed from, in order; None: the
    # plan came from the planner. Stored only when set
    chain: SubtaskChain | None = None
    # a prompt to synthesize a new scene from for every attempt (seeded by the attempt's seed); None:
    # the plan's layout (or ``synthesized``). Stored only when set
    synthesis: SynthesisRequest | None = None
    # recovery data (`vcage.skills.recovery`): executed commands pushed off the plan on a share of the
    # motion segments, the plan's command kept as the action; None: off. Stored only when set
    recovery: RecoveryConfig | None = None

    def __post_init__(self) -> None:
        seed = self.seed
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < SEED_LIMIT:
            raise ConfigError(f"seed must be an integer in [0, 2**32), got {seed!r}")
        attempts = self.max_attempts
        if isinstance(attempts, bool) or not isinstance(attempts, int) or attempts < 1:
            raise ConfigError(f"max_attempts must be an integer >= 1, got {attempts!r}")
        if self.synthesis is not None and (self.synthesized is not None or self.chain is not None):
            given = "a synthesized scene" if self.synthesized is not None else "a subtask chain"
            raise ConfigError(f"the configuration asks for a scene synthesized per attempt and {given}: "
                              "one scene source; drop 'synthesis' or "
                              f"'{'synthesized' if self.synthesized is not None else 'chain'}'")

    @property
    def scene_source(self) -> str:
        """Where each attempt's scene comes from: ``layout`` (the plan's objects placed afresh),
        ``scene`` (a synthesized scene), ``synthesis`` (a scene synthesized for every attempt) or
        ``chain`` (a chain of verified subtasks, which brings its scene); :mod:`.job` resolves it."""
        if self.synthesis is not None:
            return "synthesis"
        if self.chain is not None:
            return "chain"
        return "scene" if self.synthesized is not None else "layout"

    @classmethod
    def vanilla(cls, **fields: Any) -> GenerateConfig:
        """The paper's baseline: naive placement, no scene check, no critic (``fields`` override;
        ``clutter`` sets the scene's clutter)."""
        scene = SceneConfig(placement="naive", clutter=fields.pop("clutter", 4), check=False)
        return cls(**{"scene": scene, "critic": None, **fields})

    @property
    def mode(self) -> str:
        """``vanilla`` for a run without critic, else ``vcage`` (a label for reports)."""
        return "vanilla" if self.critic is None else "vcage"

    def resolved(self) -> GenerateConfig:
        """This config with unset model endpoints read from the environment (``VCAGE_LLM_*`` for the
        LLM planner, ``VCAGE_VLM_*`` for the VLM critic), so the run records what it used."""
        cfg = self
        if cfg.planner.name == "llm" and cfg.planner.backend is None:
            cfg = replace(cfg, planner=replace(cfg.planner, backend=BackendConfig.from_env(LLM_ENV_PREFIX)))
        if cfg.critic is not None and cfg.critic.name == "vlm" and cfg.critic.backend is None:
            cfg = replace(cfg, critic=replace(cfg.critic, backend=BackendConfig.from_env(VLM_ENV_PREFIX)))
        return cfg

    def to_dict(self) -> dict[str, Any]:
        data = {"seed": self.seed, "max_attempts": self.max_attempts,
                "planner": self.planner.to_dict(), "scene": self.scene.to_dict(),
                "critic": self.critic.to_dict() if self.critic else None,
                "render": self.render.to_dict(), "sim": self.sim.to_dict(),
                "randomization": self.randomization.to_dict(), "executor": self.executor.to_dict()}
        if self.synthesized is not None:
            data["synthesized"] = self.synthesized.to_dict()
        if self.chain is not None:
            data["chain"] = self.chain.to_dict()
        if self.synthesis is not None:
            data["synthesis"] = self.synthesis.to_dict()
        if self.recovery is not None:
            data["recovery"] = self.recovery.to_dict()
        return data

    def data_dict(self) -> dict[str, Any]:
        """What must match to append to a dataset: everything but where episodes ran and how
        model endpoints are reached (timeouts, retries, the key's variable)."""
        data = self.to_dict()
        del data["executor"]
        for part in ("planner", "critic"):
            backend = (data[part] or {}).get("backend") or {}
            for key in TRANSPORT:
                backend.pop(key, None)
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> GenerateConfig:
        return from_fields(cls, data, planner=PlannerConfig, scene=SceneConfig, critic=CriticConfig,
                           render=RenderConfig, sim=SimConfig, randomization=Randomization,
                           executor=ExecutorConfig, synthesized=SynthesizedScene,
                           chain=SubtaskChain, synthesis=SynthesisRequest, recovery=RecoveryConfig)

    def episode_seed(self, episode: int, attempt: int) -> int:
        """The seed of an attempt: derived from the run seed, the episode and the attempt index."""
        return int(np.random.SeedSequence([self.seed, episode, attempt]).generate_state(1)[0])
