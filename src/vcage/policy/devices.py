"""The torch device a command was asked to use, checked before any work starts."""

from __future__ import annotations

import torch

from vcage.errors import ConfigError


def torch_device(name: str) -> torch.device:
    """``cpu``, ``cuda`` or ``cuda:N`` (when this machine has that GPU); ConfigError otherwise."""
    try:
        device = torch.device(name)
    except (RuntimeError, TypeError) as exc:
        raise ConfigError(f"unknown device {name!r} ({exc}); use cpu, or cuda when a GPU is "
                          "present") from None
    if device.type == "cpu":
        return device
    if device.type == "cuda" and torch.cuda.is_available() \
            and (device.index is None or device.index < torch.cuda.device_count()):
        return device
    raise ConfigError(f"device {name!r} is not available on this machine; use cpu")
