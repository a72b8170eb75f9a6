from __future__ import annotations

import pytest

from vcage.config import Randomization, Range, SimConfig
from vcage.errors import ConfigError, RegistryError, VcageError
from vcage.registry import Registry


def test_registry_rejects_duplicates_and_lists_valid_names() -> None:
    reg: Registry[int] = Registry("widget")
    reg.add("a", 1)
    reg.add("b", 2)
    with pytest.raises(RegistryError, match="already registered"):
        reg.add("a", 3)
    with pytest.raises(RegistryError, match="valid names: a, b"):
        reg.get("c")
    assert reg.names() == ["a", "b"] and "a" in reg and len(reg) == 2


def test_errors_share_one_hierarchy() -> None:
    assert issubclass(ConfigError, VcageError) and issubclass(RegistryError, VcageError)


@pytest.mark.parametrize("low, high", [(1.0, 0.0), (float("nan"), 1.0), (0.0, float("inf"))])
def test_range_refuses_invalid_bounds(low: float, high: float) -> None:
    with pytest.raises(ConfigError):
        Range(low, high)


def test_randomization_refuses_out_of_bounds_ranges() -> None:
    with pytest.raises(ConfigError, match="scale"):
        Randomization(scale=Range(0.1, 2.0))
    with pytest.raises(ConfigError, match="unknown randomization keys"):
        Randomization.from_dict({"gravity": [0, 1]})
    with pytest.raises(ConfigError, match="low"):
        Randomization.from_dict({"object_xy": [0.05, -0.05]})
    r = Randomization.from_dict({"object_xy": [-0.01, 0.01], "color": False})
    assert r.object_xy == Range(-0.01, 0.01) and r.color is False
    assert Randomization.from_dict(r.to_dict()) == r


def test_sim_config_requires_whole_substeps() -> None:
    assert SimConfig().substeps == 25
    with pytest.raises(ConfigError):
        SimConfig(timestep=0.003, control_hz=20.0)


def test_the_public_api_resolves_every_name_it_lists() -> None:
    import vcage

    for name in vcage.__all__:
        assert getattr(vcage, name) is not None, name
    assert "generate" in dir(vcage)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        vcage.nope  # noqa: B018
