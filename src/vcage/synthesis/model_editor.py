"""The image editor backed by an image model: ``I_goal = M(I_init, D_scene)`` over a provider's API.

It sends ``I_init`` (and, by default, the empty table as a second reference image) with an
instruction built from ``D_scene``'s text to an :class:`~vcage.backends.images.ImageEditBackend`
(Gemini's ``generateContent`` or an OpenAI-compatible ``/images/edits``). A ``blocked`` or
``no_image`` answer is resampled (a fresh seed) at most ``resamples`` times, then refused with
:class:`ImageEditError`; an image that does not decode, or whose aspect ratio differs from
``I_init``'s, is refused at once. An image of ``I_init``'s aspect ratio at another resolution (models
draw at their own) is resampled to ``I_init``'s size when ``rescale`` is on; the info says so.
Outages (:class:`~vcage.errors.BackendUnavailableError`) are not refusals and propagate.
"""

from __future__ import annotations

import io
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from vcage.backends.images import ImageEditBackend
from vcage.backends.messages import encode_png
from vcage.errors import ConfigError
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.editing import EditResult, ImageEditor
from vcage.synthesis.errors import ImageEditError
from vcage.synthesis.views import TopView

ASPECT_TOLERANCE = 0.01  # relative difference of width/height accepted as the same aspect ratio
MAX_RESAMPLES = 5


@dataclass(frozen=True)
class ModelEditorConfig:
    resamples: int = 2  # new requests after a blocked or imageless answer
    send_empty: bool = True  # also send the empty table, so the model knows the background
    rescale: bool = True  # resample an image of the right aspect ratio to I_init's size

    def __post_init__(self) -> None:
        if isinstance(self.resamples, bool) or not isinstance(self.resamples, int) or not (
                0 <= self.resamples <= MAX_RESAMPLES):
            raise ConfigError(f"resamples must be an integer in [0, {MAX_RESAMPLES}], got {self.resamples!r}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def edit_prompt(desc: SceneDescription, with_empty: bool) -> str:
    """The instruction for the image model: rearrange, keep everything else, keep the frame."""
    names = ", ".join(f"{o.color + ' ' if o.color else ''}{o.type.replace('_', ' ')}" for o in desc.objects)
    empty = (" The second image shows the same table with no objects: use it as the background."
             if with_empty else "")
    return (
        "The first image is an orthographic top-down photo of a robot's table. Edit it so that the "
        f"objects on it are rearranged as described: {desc.text}\n"
        f"Objects: {names}. Move only these objects, each one whole, keeping its shape, size, colour "
        "and look; do not add, remove or duplicate objects; leave the table, the robot and the "
        f"lighting unchanged; keep the camera, the framing and the image size exactly.{empty} "
        "Answer with the edited image."
    )


def decode_image(data: bytes) -> np.ndarray:
    """``data`` (PNG, JPEG, WebP...) as an (H, W, 3) uint8 array; :class:`ImageEditError` if garbage."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(io.BytesIO(data)) as im:
            return np.asarray(im.convert("RGB"))
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        raise ImageEditError(f"the image model's answer is not a readable image ({len(data)} bytes: "
                             f"{exc}); check the endpoint returns image files") from None


def fit_size(image: np.ndarray, init: TopView, rescale: bool) -> tuple[np.ndarray, bool]:
    """``image`` at ``init``'s size, and whether it was resampled; wrong aspect ratios are refused."""
    h, w = init.rgb.shape[:2]
    gh, gw = image.shape[:2]
    if (gh, gw) == (h, w):
        return image, False
    same_aspect = abs(gw / gh - w / h) <= ASPECT_TOLERANCE * (w / h)
    if not (rescale and same_aspect):
        why = "rescaling is off" if same_aspect else "its aspect ratio differs, so it cannot be registered"
        raise ImageEditError(f"the goal image is {gw}x{gh}, not the initial image's {w}x{h} and {why}: "
                             "ask the model to keep the image size (or allow rescaling)")
    from PIL import Image

    return np.asarray(Image.fromarray(image).resize((w, h), Image.Resampling.LANCZOS)), True


class ModelEditor(ImageEditor):
    name = "model"

    def __init__(self, backend: ImageEditBackend, config: ModelEditorConfig | None = None) -> None:
        self.backend = backend
        self.config = config or ModelEditorConfig()

    def edit(self, init: TopView, empty: np.ndarray, desc: SceneDescription,
             rng: np.random.Generator) -> EditResult:
        cfg = self.config
        prompt = edit_prompt(desc, cfg.send_empty)
        images = [encode_png(init.rgb)]
        if cfg.send_empty:
            images.append(encode_png(np.ascontiguousarray(empty)))
        answers: list[dict[str, Any]] = []
        for _ in range(1 + cfg.resamples):
            answer = self.backend.edit(prompt, images, seed=int(rng.integers(2**31)))
            answers.append(answer.to_dict())
            if answer.outcome != "image":
                continue
            assert answer.image is not None
            image, rescaled = fit_size(decode_image(answer.image), init, cfg.rescale)
            info: dict[str, object] = {
                "editor": self.name, "backend": self.backend.name, "model": self.backend.config.model,
                "prompt": prompt, "answers": answers,
                "rescaled_from": answer_size(answer.image) if rescaled else None}
            return EditResult(image, info=info)
        outcomes = "; ".join(f"{a['outcome']}: {a['detail']}" for a in answers)
        raise ImageEditError(f"the image model ({self.backend.config.model!r} at {self.backend.edit_url}) "
                             f"gave no goal image in {len(answers)} request(s): {outcomes}. Rephrase the "
                             "prompt, raise resamples, or use another image model")


def answer_size(data: bytes) -> list[int]:
    from PIL import Image

    with Image.open(io.BytesIO(data)) as im:
        return [int(im.width), int(im.height)]
