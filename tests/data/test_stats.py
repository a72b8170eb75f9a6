"""Per-episode image stats equal the stats of the sampled pixels themselves."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.data.stats import IMAGE_SAMPLE_FRAMES, IMAGE_SAMPLE_SIDE, image_stats


@pytest.mark.parametrize("shape", [(250, 128, 128, 3), (7, 480, 640, 3), (1, 2, 3, 3)])
def test_image_stats_are_those_of_the_sampled_pixels(shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(sum(shape))
    frames = rng.integers(40, 200, shape, dtype=np.uint8)
    frames[-1, 0, 0] = (0, 255, 17)  # each channel's extremes sit in one pixel of a sampled frame
    picks = np.unique(np.linspace(0, shape[0] - 1, min(shape[0], IMAGE_SAMPLE_FRAMES)).round().astype(int))
    stride = max(1, max(shape[1:3]) // IMAGE_SAMPLE_SIDE)
    pixels = frames[picks, ::stride, ::stride].reshape(-1, 3) / 255.0
    stats = image_stats(frames)
    for name, want in (("min", pixels.min(0)), ("max", pixels.max(0)), ("mean", pixels.mean(0)),
                       ("std", pixels.std(0))):
        assert stats[name].shape == (3, 1, 1)
        np.testing.assert_allclose(stats[name].ravel(), want, rtol=0, atol=1e-12, err_msg=name)
    assert stats["count"].tolist() == [len(picks)]


def test_image_stats_refuse_frames_that_are_not_bytes() -> None:
    with pytest.raises(ValueError, match="uint8"):
        image_stats(np.zeros((2, 4, 4, 3), np.float32))
