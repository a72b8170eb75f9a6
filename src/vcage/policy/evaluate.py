"""Evaluating a checkpoint: rollouts in its dataset's evaluation environment, success statistics.

The environment comes from :func:`vcage.pipeline.evaluation.make_env` with the configuration the
dataset stored (``meta/vcage.json``), or another dataset's. Before any rollout the checkpoint's
observation features (names, sizes, element names), action (name and size) and control rate are
checked against the environment's; a difference raises :class:`EnvironmentMismatchError`. The
environment is asked for the checkpoint's action (``make_env(..., action=...)``: joint targets, or
the tool's pose, which it turns into joint targets by IK).

An environment raises :class:`~vcage.errors.SimulationError` where its physics fails (the contract of
:mod:`vcage.tasks.env`); a policy can drive it there (a lurch into objects an unchecked scene left
fused together). Such an episode ends as a failure that says so (``EpisodeResult.unstable``, counted
apart in :attr:`Evaluation.unstable`), and the evaluation goes on: one rollout does not lose the others.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch

from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.config import ACTION
from vcage.policy.dataset import FeatureSpec
from vcage.policy.devices import torch_device
from vcage.policy.ensemble import TemporalEnsemble
from vcage.policy.errors import EnvironmentMismatchError, PolicyError
from vcage.policy.inference import PolicyRunner
from vcage.policy.metrics import subtask_reached, wilson_interval
from vcage.policy.rollout import Blocks, EnvFactory, EpisodeResult, blocks, parallel, rollout


@dataclass(frozen=True)
class Evaluation:
    """The episodes of one evaluation and their statistics."""

    checkpoint: str
    seed: int
    episodes: tuple[EpisodeResult, ...]
    seconds: float
    subtask_names: tuple[str, ...] = ()  # the plan's subtask descriptions, when the config has a plan
    ensemble: TemporalEnsemble | None = None  # how chunks became actions (None: n_action_steps of each)

    @property
    def successes(self) -> int:
        return sum(e.success for e in self.episodes)

    @property
    def success_rate(self) -> float:
        return self.successes / len(self.episodes) if self.episodes else 0.0

    @property
    def unstable(self) -> int:
        """How many episodes ended because the physics failed (counted as failures)."""
        return sum(e.unstable is not None for e in self.episodes)

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.successes, len(self.episodes))

    @property
    def subtask_progress(self) -> list[float]:
        """Share of the episodes that completed each subtask (in the plan's order)."""
        n = max((e.subtasks for e in self.episodes), default=len(self.subtask_names))
        return subtask_reached([e.subtasks_done for e in self.episodes], n)

    @property
    def mean_progress(self) -> float:
        return float(np.mean([e.progress for e in self.episodes])) if self.episodes else 0.0

    @property
    def rollouts_per_minute(self) -> float:
        return 60 * len(self.episodes) / self.seconds if self.seconds > 0 else 0.0

    def to_dict(self) -> dict[str, Any]:
        low, high = self.interval
        return {"checkpoint": self.checkpoint, "seed": self.seed, "episodes": len(self.episodes),
                "successes": self.successes, "success_rate": self.success_rate, "unstable": self.unstable,
                "wilson95": [low, high], "subtask_progress": self.subtask_progress,
                "subtask_names": list(self.subtask_names), "mean_progress": self.mean_progress,
                "ensemble": self.ensemble.to_dict() if self.ensemble is not None else None,
                "seconds": self.seconds, "rollouts_per_minute": self.rollouts_per_minute,
                "per_episode": [asdict(e) for e in self.episodes]}


def check_compatible(checkpoint: Mapping[str, Any], env: gym.Env) -> None:
    """EnvironmentMismatchError naming every difference between what the policy was trained on and
    what ``env`` observes, takes as action, and steps at."""
    problems = []
    space = env.observation_space
    spaces = getattr(space, "spaces", {})
    env_features = getattr(env.unwrapped, "features", {})
    for data in checkpoint["obs_features"]:
        spec = FeatureSpec.from_dict(data)
        name = spec.feature
        if name not in spaces:
            problems.append(f"the environment has no observation {name!r} (it has "
                            f"{', '.join(sorted(spaces))})")
            continue
        shape = tuple(spaces[name].shape or ())
        env_names = getattr(env_features.get(name), "names", None)
        if spec.indices is not None:  # some elements of the feature, by name
            if not env_names or len(shape) != 1 or max(spec.indices) >= shape[0] \
                    or [env_names[i] for i in spec.indices] != list(spec.names or ()):
                problems.append(f"observation {spec.name!r} reads elements {list(spec.names or ())} of "
                                f"{name!r}, which the environment does not have at the same places")
            continue
        if shape != (spec.size,):
            problems.append(f"observation {name!r} is {shape} in the environment, ({spec.size},) in the "
                            "checkpoint")
            continue
        if spec.names and env_names and list(env_names) != list(spec.names):
            problems.append(f"observation {name!r} has elements {list(env_names)[:4]}... in the "
                            f"environment, {list(spec.names)[:4]}... in the checkpoint (other "
                            "objects or order)")
    action = int(checkpoint["action_feature"]["size"])
    if tuple(env.action_space.shape or ()) != (action,):
        problems.append(f"the action is {env.action_space.shape} in the environment, ({action},) in the "
                        "checkpoint")
    name, env_name = checkpoint["action_feature"]["name"], getattr(env.unwrapped, "action_key", ACTION)
    if name != env_name:
        problems.append(f"the environment takes {env_name!r} as its action, the checkpoint predicts {name!r}")
    subtasks, plan = int(checkpoint.get("subtasks", 0)), getattr(env.unwrapped, "plan", None)
    if subtasks and plan is not None and len(plan.subtasks) != subtasks:
        problems.append(f"the policy is conditioned on {subtasks} subtasks, the environment's plan has "
                        f"{len(plan.subtasks)}")
    fps, env_fps = int(checkpoint["dataset"]["fps"]), env.metadata.get("render_fps")
    if env_fps is not None and int(env_fps) != fps:
        problems.append(f"the environment steps at {env_fps} Hz, the dataset was recorded at {fps} fps")
    if problems:
        raise EnvironmentMismatchError(f"the checkpoint {checkpoint.get('path', '')} does not fit this "
                                       f"environment: {'; '.join(problems)}; evaluate it in the environment "
                                       "of the dataset it was trained on")



def training_scenes(checkpoint: Mapping[str, Any], count: int) -> list[int]:
    """The scene seeds of the first ``count`` episodes of the dataset ``checkpoint`` was trained on
    (all of them if it has fewer): rolling out on them asks whether the policy reproduces its own
    demonstrations, which tells a policy that cannot fit its data from one that does not generalise."""
    return dataset_scenes(checkpoint["dataset"]["path"], count)


def dataset_scenes(path: str | Path, count: int) -> list[int]:
    """The scene seeds of the first ``count`` episodes of the vcage dataset at ``path`` (all of them
    if it has fewer); PolicyError if it cannot be read or does not store them."""
    from vcage.data.reader import DatasetReader
    from vcage.errors import DatasetError

    try:
        reader = DatasetReader(path)
        seeds = [reader.extras(i).get("seed") for i in range(min(count, reader.num_episodes))]
    except DatasetError as exc:
        raise PolicyError(f"the training scenes are those of the dataset the checkpoint was trained on, "
                          f"and it cannot be read at {path} ({exc}); evaluate on held-out scenes") from None
    found = [s for s in seeds if isinstance(s, int)]
    if not found or len(found) < len(seeds):
        raise PolicyError(f"the dataset {path} does not store its episodes' scene seeds (a dataset not "
                          "written by vcage generate); evaluate on held-out scenes")
    return found


def default_factory() -> EnvFactory:
    from vcage.pipeline.evaluation import make_env

    return make_env


def evaluate(checkpoint: str | Path, episodes: int, *, seed: int = 0, max_steps: int | None = None,
             env_config: dict[str, Any] | None = None, device: str = "cpu", threads: int | None = None,
             make_env: EnvFactory | None = None,
             progress: Callable[[int, int, EpisodeResult], None] | None = None,
             workers: int = 1, scenes: Sequence[int] | None = None, batch: int = 1,
             ensemble: TemporalEnsemble | None = None) -> Evaluation:
    """Roll out ``checkpoint`` (a file, or a training run's directory: its latest) for ``episodes``
    episodes of the environment of ``env_config`` (default: the configuration of the dataset it was
    trained on), seeded ``seed``; ``threads`` caps torch's CPU threads for the duration.

    Episode ``k`` is the environment's episode ``k`` with the sampler noise of
    :func:`~vcage.policy.rollout.episode_noise_seed`, so ``workers`` processes (each rolling out
    its share, with ``threads`` torch threads, default 1) give the same episodes as one. More than
    one worker needs an environment that can start episode ``k`` directly (``episode_option``, as
    ``GoalEnv``) and a picklable ``make_env``. ``scenes`` (scene seeds, e.g.
    :func:`training_scenes`) replaces the environment's own evaluation scenes: episode ``k`` builds
    ``scenes[k % len(scenes)]``.

    ``batch`` > 1 steps the episodes in consecutive blocks of that many together and samples their
    chunks as one batch (:func:`~vcage.policy.rollout.rollout_block`): several times cheaper per
    episode for a diffusion policy on a CPU. Results then depend on ``batch`` (not on ``workers``,
    which share whole blocks): a batch's arithmetic can differ from one-at-a-time passes in the last
    bits. ``ensemble``: the runners' temporal ensembling (:mod:`vcage.policy.ensemble`; None
    executes ``n_action_steps`` of each chunk)."""
    if episodes < 1:
        raise PolicyError(f"--episodes must be at least 1, got {episodes}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise PolicyError(f"--workers must be a positive integer, got {workers!r}")
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise PolicyError(f"--batch must be a positive integer, got {batch!r}")
    torch_device(device)
    payload = load_checkpoint(checkpoint)
    config = env_config if env_config is not None else payload["dataset"].get("config")
    if not config:
        raise PolicyError(f"the dataset {payload['dataset']['path']} the checkpoint was trained on stores no "
                          "vcage configuration (meta/vcage.json), so there is no environment to evaluate in; "
                          "pass the environment of a vcage dataset (--env DATASET)")
    factory = functools.partial(make_env or default_factory(), action=payload["action_feature"]["name"])
    if scenes is not None:
        if not scenes:
            raise PolicyError("an evaluation on given scenes needs at least one scene seed")
        factory = functools.partial(factory, scenes=list(scenes))
    env = factory(config, seed=seed, max_steps=max_steps)
    old_threads = torch.get_num_threads()
    if threads is not None:
        torch.set_num_threads(threads)
    try:
        check_compatible(payload, env)
        direct = bool(getattr(env.unwrapped, "episode_option", False))
        if workers > 1 and not direct:
            raise PolicyError("this environment cannot start an episode by its index, so its episodes "
                              "cannot be shared among workers; evaluate with --workers 1")
        if batch > 1 and not direct:
            raise PolicyError("this environment cannot start an episode by its index, so its episodes "
                              "cannot be stepped in batches; evaluate with --batch 1")
        began = time.perf_counter()
        groups = blocks(episodes, batch)
        if workers > 1 and len(groups) > 1:
            env.close()
            results = parallel(str(payload["path"]), groups, min(workers, len(groups)), factory, config,
                                seed=seed, max_steps=max_steps, device=device, threads=threads or 1,
                                progress=progress, ensemble=ensemble)
        elif batch > 1:
            blocks_here = Blocks(payload, factory, config, seed=seed, max_steps=max_steps, device=device,
                                 envs=[env], ensemble=ensemble)
            results = []
            try:
                for group in groups:
                    results += blocks_here.run(group)
                    if progress is not None:
                        for result in results[-len(group):]:
                            progress(len(results), episodes, result)
            finally:
                blocks_here.close(keep=1)  # the first environment is ``env``, closed below
        else:
            runner = PolicyRunner(payload, device=device, seed=seed, ensemble=ensemble)
            results = []
            for k in range(episodes):
                if direct:  # every episode restarts from the seed: k depends on nothing before it
                    results.append(rollout(runner, env, seed, episode=k))
                else:
                    results.append(rollout(runner, env, seed if k == 0 else None))
                if progress is not None:
                    progress(k + 1, episodes, results[-1])
        seconds = time.perf_counter() - began
    finally:
        env.close()
        torch.set_num_threads(old_threads)
    return Evaluation(str(payload["path"]), seed, tuple(results), seconds, subtask_names(config), ensemble)



def subtask_names(config: Mapping[str, Any]) -> tuple[str, ...]:
    """The descriptions of the plan's subtasks in a dataset configuration (empty if it has no plan)."""
    plan = config.get("plan") if isinstance(config, Mapping) else None
    subtasks = plan.get("subtasks") if isinstance(plan, Mapping) else None
    if not isinstance(subtasks, list):
        return ()
    return tuple(str(s.get("description") or s.get("skill") or f"subtask {i}") if isinstance(s, Mapping)
                 else f"subtask {i}" for i, s in enumerate(subtasks))
