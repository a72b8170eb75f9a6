"""Chat messages and the one image format they carry: PNG, which every provider accepts inline."""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vcage.errors import ConfigError

ROLES = ("system", "user", "assistant")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def encode_png(image: bytes | np.ndarray) -> bytes:
    """PNG bytes of ``image``: PNG bytes are returned unchanged, a uint8 HxWx3 array is encoded."""
    if isinstance(image, (bytes, bytearray, memoryview)):
        data = bytes(image)
        if not data.startswith(PNG_SIGNATURE):
            raise ConfigError("image bytes must be a PNG file; encode other formats as PNG first")
        return data
    if isinstance(image, np.ndarray):
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 3 or 0 in image.shape:
            raise ConfigError(
                f"image array must be uint8 with shape (H, W, 3), got {image.dtype} {image.shape}"
            )
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG")
        return buf.getvalue()
    raise ConfigError(f"image must be PNG bytes or a uint8 (H, W, 3) numpy array, got {type(image).__name__}")


@dataclass(frozen=True)
class Message:
    """One chat message; ``images`` (PNG bytes or uint8 HxWx3 arrays) are stored as PNG bytes."""

    role: str
    text: str
    images: tuple[bytes, ...] = ()

    def __init__(self, role: str, text: str, images: Sequence[bytes | np.ndarray] = ()) -> None:
        if role not in ROLES:
            raise ConfigError(f"message role {role!r} is invalid; use one of {list(ROLES)}")
        if not isinstance(text, str):
            raise ConfigError(f"message text must be a str, got {type(text).__name__}")
        if images and role != "user":
            raise ConfigError(f"images can only be attached to 'user' messages, not {role!r}")
        object.__setattr__(self, "role", role)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "images", tuple(encode_png(im) for im in images))
