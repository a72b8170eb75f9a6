"""Control-step throughput of the pipeline versus raw ``mj_step`` on the same model.

    .venv/bin/python benchmarks/stepping.py

Three loops advance the same scene by the same number of physics steps with the same controls:
raw ``mujoco.mj_step`` called once per physics step from Python (the baseline), ``World.step``
(one control period with the instability check), and the player's tick (World.step plus
recording joints, gripper, TCP pose and action). Ratios are time relative to the baseline.
"""

from __future__ import annotations

import time

import mujoco
import numpy as np

from vcage.config import Randomization
from vcage.sim.robot import HOME_QPOS
from vcage.skills.playback import Player
from vcage.tasks import prepare

CONTROL_STEPS = 2000


def _best_of(fn, repeats: int = 5) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    _, world, _ = prepare("stack_blocks_three", 0, Randomization.off())
    model, data = world.model, world.data
    ctrl = world.robot.ctrl(HOME_QPOS, 1.0)
    start = world.get_state()
    n_sub = world.substeps

    def raw() -> None:
        world.set_state(start)
        data.ctrl[:] = ctrl
        for _ in range(CONTROL_STEPS * n_sub):
            mujoco.mj_step(model, data)

    def pipeline() -> None:
        world.set_state(start)
        for _ in range(CONTROL_STEPS):
            world.step(ctrl)

    player = Player(world)

    def player_tick() -> None:
        world.set_state(start)
        player.recording.__init__()  # type: ignore[misc]
        for _ in range(CONTROL_STEPS):
            player._tick(HOME_QPOS, 1.0)

    t_raw, t_pipe, t_exec = _best_of(raw), _best_of(pipeline), _best_of(player_tick)
    phys = CONTROL_STEPS * n_sub
    print(f"scene: stack_blocks_three (nq={model.nq}, nbody={model.nbody}), timestep "
          f"{model.opt.timestep * 1000:.0f} ms, {n_sub} physics steps per control step, "
          f"{CONTROL_STEPS} control steps, best of 5\n")
    print(f"{'loop':34s} {'physics steps/s':>16s} {'ratio to raw':>13s}")
    for name, t in (("raw mj_step (baseline)", t_raw), ("World.step (pipeline)", t_pipe),
                    ("Player tick (with recording)", t_exec)):
        print(f"{name:34s} {phys / t:16,.0f} {t / t_raw:13.3f}")
    np.testing.assert_allclose(world.robot.arm_q(data), HOME_QPOS, atol=0.05)


if __name__ == "__main__":
    main()
