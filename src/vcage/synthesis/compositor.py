"""The offline image editor: a deterministic compositor that moves each object's own pixels.

Each object is cut out of ``I_init`` with its segmentation mask, turned and moved in the image
exactly as a rigid motion on the table to a layout that satisfies ``D_scene`` (found by the refine
objective from the initial poses), and pasted onto the empty table, lowest first; the robot is
drawn back over everything. Optional :mod:`~vcage.synthesis.perturb` perturbations make it look
like a model's redraw. The drawn poses come back as ground truth.
"""

from __future__ import annotations

import numpy as np

from vcage.scene.spec import TableSpec
from vcage.sim.render import ROBOT
from vcage.synthesis.costs import Problem
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.editing import EDITORS, EditResult, ImageEditor
from vcage.synthesis.perturb import Perturbation, global_transform, photometric
from vcage.synthesis.refine import RefineConfig, refine
from vcage.synthesis.views import TopView


def warp_object(view: TopView, name: str,
                target: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The object's pixels and mask (float) moved to ``target`` (x, y, yaw), full-frame."""
    from PIL import Image

    x0, y0, yaw0 = view.poses[name]
    cam = view.camera
    z = view.heights[name]
    c0 = cam.to_pixel(np.array([[x0, y0]]), z)[0]
    c1 = cam.to_pixel(np.array([[target[0], target[1]]]), z)[0]
    angle = np.radians(cam.image_angle(target[2] - yaw0))
    # output pixel q -> input pixel p = R(-angle) (q - c1) + c0, with R counter-clockwise as displayed
    c, s = np.cos(angle), np.sin(angle)
    a, b, d, e = c, -s, s, c  # rotation by +angle as displayed (v down): [[c, s], [-s, c]] inverse
    inv = (a, b, c0[0] - a * c1[0] - b * c1[1], d, e, c0[1] - d * c1[0] - e * c1[1])
    h, w = view.rgb.shape[:2]
    mask = (view.mask(name) * 255).astype(np.uint8)
    rgb = Image.fromarray(view.rgb).transform((w, h), Image.Transform.AFFINE, inv, Image.Resampling.BILINEAR)
    m = Image.fromarray(mask).transform((w, h), Image.Transform.AFFINE, inv, Image.Resampling.BILINEAR)
    return np.asarray(rgb), np.asarray(m).astype(np.float32) / 255.0


def goal_layout(desc: SceneDescription, view: TopView, table: TableSpec,
                rng: np.random.Generator) -> dict[str, tuple[float, float, float]]:
    """Poses satisfying ``desc`` near the initial ones (the layout the compositor draws)."""
    problem = Problem.build(desc, table, margin=0.015)
    return refine(problem, {n: view.poses[n] for n in problem.names}, RefineConfig(), rng).poses


def paint_order(desc: SceneDescription, poses: dict[str, tuple[float, float, float]]) -> list[str]:
    def depth(name: str) -> int:
        d, cur = 0, desc.support_of(name)
        while cur is not None and d < len(desc.objects):
            d, cur = d + 1, desc.support_of(cur.b)
        return d
    return sorted(poses, key=lambda n: (depth(n), n))


class Compositor(ImageEditor):
    name = "compositor"

    def __init__(self, perturbation: Perturbation | None = None, table: TableSpec | None = None) -> None:
        self.perturbation = perturbation or Perturbation()
        self.table = table or TableSpec()

    def edit(self, init: TopView, empty: np.ndarray, desc: SceneDescription,
             rng: np.random.Generator) -> EditResult:
        poses = goal_layout(desc, init, self.table, rng)
        if self.perturbation.turn:
            span = np.radians(self.perturbation.turn)
            poses = {n: (x, y, yaw + float(rng.uniform(-span, span))) for n, (x, y, yaw) in poses.items()}
        dropped: tuple[str, ...] = ()
        if self.perturbation.drop:
            hosts = {r.b for r in desc.relations if r.kind in ("on", "inside")}
            free = [n for n in poses if n not in hosts]
            if free:
                dropped = (free[int(rng.integers(len(free)))],)
        canvas = empty.astype(np.float32)
        for name in paint_order(desc, poses):
            if name in dropped:
                continue
            rgb, mask = warp_object(init, name, poses[name])
            canvas = canvas * (1 - mask[..., None]) + rgb.astype(np.float32) * mask[..., None]
        robot = init.segmentation == ROBOT
        canvas[robot] = init.rgb[robot]
        image = np.clip(canvas + 0.5, 0, 255).astype(np.uint8)
        image, applied = global_transform(image, self.perturbation, rng)
        image = photometric(image, self.perturbation, rng)
        truth = {n: p for n, p in poses.items() if n not in dropped}
        info = {"editor": self.name, "perturbation": self.perturbation.to_dict(),
                "global_shift_px": applied.shift, "global_scale": applied.scale}
        return EditResult(image, truth, dropped, info)


EDITORS.add("compositor", Compositor)
