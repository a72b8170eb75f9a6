"""The image-model editor through the real SDKs and local servers: goal images, bounded resampling of
blocked or imageless answers, typed refusals of garbage and wrong sizes, and a whole synthesis run."""

from __future__ import annotations

import base64
import io
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from backends.fake_gemini import FakeGemini
from backends.fake_images import (
    FakeImagesOpenAI,
    gemini_image,
    gemini_prompt_block,
    gemini_text_only,
    moderation_block,
    openai_image,
)
from backends.fake_openai import Raw, Status
from vcage.backends import BackendConfig
from vcage.backends.images import connect_images
from vcage.errors import BackendUnavailableError, ConfigError
from vcage.synthesis.description import parse_description
from vcage.synthesis.driver import DirectorySink, SynthesisConfig, synthesize
from vcage.synthesis.editors import EditorConfig, make_editor
from vcage.synthesis.errors import ImageEditError, SynthesisError
from vcage.synthesis.model_editor import ModelEditor, ModelEditorConfig, edit_prompt
from vcage.synthesis.views import TopView

H, W = 48, 64
DESC = parse_description({"prompt": "a mug next to a plate", "text": "a mug beside a plate",
                          "objects": [{"name": "mug", "type": "mug"}, {"name": "plate", "type": "plate"}],
                          "relations": [{"kind": "near", "a": "mug", "b": "plate"}]})


def b64decode(text: str) -> bytes:
    """What the SDK sent: base64, standard or URL-safe, padded or not."""
    return base64.b64decode(text.replace("-", "+").replace("_", "/") + "=" * (-len(text) % 4))


def picture(w: int = W, h: int = H, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 255, (h, w, 3), dtype=np.uint8)


def encoded(image: np.ndarray, fmt: str = "PNG") -> bytes:
    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format=fmt)
    return buf.getvalue()


def view(rgb: np.ndarray) -> TopView:
    return TopView(rgb, np.full(rgb.shape[:2], -1), (), None, {}, {}, 0.75)  # type: ignore[arg-type]


@pytest.fixture()
def gemini() -> Iterator[FakeGemini]:
    with FakeGemini() as srv:
        yield srv


def editor(url: str, provider: str = "gemini", resamples: int = 2, **kw: Any) -> ModelEditor:
    cfg = BackendConfig(base_url=url, model="image-model", provider=provider, timeout=5.0, max_retries=1,
                        backoff=0.01)
    return ModelEditor(connect_images(cfg), ModelEditorConfig(resamples=resamples, **kw))


def test_goal_image_and_what_was_asked(gemini: FakeGemini) -> None:
    init, goal = picture(), picture(seed=1)
    gemini.script(gemini_image(encoded(goal), thoughts=(encoded(picture(seed=2)),)))
    result = editor(gemini.base_url).edit(view(init), picture(seed=3), DESC, np.random.default_rng(0))
    assert np.array_equal(result.image, goal) and result.truth is None
    parts = gemini.requests[0]["contents"][0]["parts"]
    assert parts[0]["text"] == edit_prompt(DESC, True) and "a mug beside a plate" in parts[0]["text"]
    sent = [np.asarray(Image.open(io.BytesIO(b64decode(p["inlineData"]["data"])))) for p in parts[1:]]
    assert np.array_equal(sent[0], init) and np.array_equal(sent[1], picture(seed=3))
    assert result.info["answers"][0]["thoughts"] == 1 and result.info["rescaled_from"] is None


def test_blocked_and_imageless_answers_are_resampled_a_bounded_number_of_times(gemini: FakeGemini) -> None:
    gemini.script(gemini_prompt_block("SAFETY"), gemini_text_only(), gemini_image(encoded(picture(seed=4))))
    result = editor(gemini.base_url, resamples=2).edit(view(picture()), picture(), DESC,
                                                      np.random.default_rng(0))
    assert [a["outcome"] for a in result.info["answers"]] == ["blocked", "no_image", "image"]
    seeds = [r["generationConfig"]["seed"] for r in gemini.requests]
    assert len(set(seeds)) == 3  # each resample asks with a fresh seed
    gemini.script(gemini_prompt_block("SAFETY"), gemini_text_only("no"), gemini_prompt_block("OTHER"))
    with pytest.raises(ImageEditError, match=r"no goal image in 3 request\(s\): blocked: .*SAFETY.*"
                                             r"no_image: .*text only"):
        editor(gemini.base_url, resamples=2).edit(view(picture()), picture(), DESC, np.random.default_rng(0))
    assert gemini.remaining == 0 and len(gemini.requests) == 6


@pytest.mark.parametrize(("answer", "message"), [
    (b"\x89PNG\r\n\x1a\n this is not an image", "not a readable image"),
    (encoded(picture(w=W + 16)), "aspect ratio differs"),
    (encoded(np.full((H, W, 3), 128, np.uint8)), "blank"),
])
def test_garbage_and_wrong_sizes_are_typed_refusals(answer: bytes, message: str) -> None:
    with FakeImagesOpenAI() as srv:
        srv.script(openai_image(answer))
        ed = editor(srv.base_url, provider="openai")
        with pytest.raises(ImageEditError, match=message):
            from vcage.synthesis.editing import check_goal_image

            check_goal_image(ed.edit(view(picture()), picture(), DESC, np.random.default_rng(0)).image,
                             view(picture()))
        assert len(srv.requests) == 1  # a refusal, not a resample


def test_a_model_drawing_at_its_own_resolution_is_rescaled() -> None:
    with FakeImagesOpenAI() as srv:
        srv.script(moderation_block(), openai_image(encoded(picture(w=2 * W, h=2 * H), "JPEG"),
                                                     output_format="jpeg"))
        result = editor(srv.base_url, provider="openai").edit(view(picture()), picture(), DESC,
                                                              np.random.default_rng(0))
        assert result.image.shape == (H, W, 3) and result.info["rescaled_from"] == [2 * W, 2 * H]
        assert [a["outcome"] for a in result.info["answers"]] == ["blocked", "image"]
        srv.script(openai_image(encoded(picture(w=2 * W, h=2 * H))))
        with pytest.raises(ImageEditError, match="rescaling is off"):
            editor(srv.base_url, provider="openai", rescale=False).edit(view(picture()), picture(), DESC,
                                                                        np.random.default_rng(0))


def test_an_outage_is_not_a_refusal(gemini: FakeGemini) -> None:
    gemini.script(Status(503), Status(503))
    with pytest.raises(BackendUnavailableError):
        editor(gemini.base_url).edit(view(picture()), picture(), DESC, np.random.default_rng(0))


def test_editor_config_round_trips_and_checks(gemini: FakeGemini) -> None:
    cfg = EditorConfig(name="model", backend=BackendConfig(base_url=gemini.base_url, model="m",
                                                           provider="gemini"))
    assert EditorConfig.from_dict(json.loads(json.dumps(cfg.to_dict()))) == cfg
    assert isinstance(make_editor(cfg), ModelEditor)
    with pytest.raises(ConfigError, match="needs a backend"):
        EditorConfig(name="model")
    with pytest.raises(ConfigError, match="unknown image editor"):
        EditorConfig(name="dalle")
    env = {"VCAGE_IMAGE_PROVIDER": "openai", "VCAGE_IMAGE_BASE_URL": "http://localhost:9/v1",
           "VCAGE_IMAGE_MODEL": "gpt-image-1"}
    assert EditorConfig.from_env(env).backend.model == "gpt-image-1"  # type: ignore[union-attr]


def echo_with_thought(body: dict[str, Any]) -> Raw:
    """A model that draws a draft, then returns the table as it was (the identity edit)."""
    first = b64decode(body["contents"][0]["parts"][1]["inlineData"]["data"])
    return gemini_image(first, thoughts=(first[: len(first) // 2],))


def test_a_synthesis_run_through_a_gemini_image_model(gemini: FakeGemini, tmp_path: Path) -> None:
    """Garbage first (refused, the next attempt starts), then an echoed table: matched, refined, settled."""
    gemini.script(Raw(200, {"candidates": [{"content": {"role": "model", "parts": [
        {"inlineData": {"mimeType": "image/png", "data": base64.b64encode(b"garbage").decode()}}]},
        "finishReason": "STOP"}]}), echo_with_thought)
    cfg = EditorConfig(name="model", backend=BackendConfig(base_url=gemini.base_url, model="gemini-image",
                                                           provider="gemini", timeout=10.0))
    out = tmp_path / "syn"
    result = synthesize("a mug next to a plate", SynthesisConfig(seed=0, attempts=2), DirectorySink(out),
                        editor=make_editor(cfg))
    funnel = json.loads((out / "funnel.json").read_text())
    assert [(f["stage"], f["status"]) for f in funnel if f["stage"] == "edit"] == [
        ("edit", "rejected"), ("edit", "ok")]
    assert "not a readable image" in next(f["detail"] for f in funnel if f["status"] == "rejected")
    assert funnel[-1]["stage"] == "settle" and funnel[-1]["status"] == "ok"
    edit = json.loads((out / "attempt-1" / "edit.json").read_text())
    assert edit["answers"][0]["thoughts"] == 1 and edit["model"] == "gemini-image"
    assert (out / "attempt-1" / "I_goal.png").is_file() and result.instance.valid
    assert len(gemini.requests) == 2


def test_a_run_whose_model_never_answers_with_an_image_ends_typed(gemini: FakeGemini, tmp_path: Path) -> None:
    gemini.script(*[gemini_prompt_block("SAFETY")] * 2)
    cfg = EditorConfig(name="model", backend=BackendConfig(base_url=gemini.base_url, model="m",
                                                           provider="gemini"),
                       model=ModelEditorConfig(resamples=1))
    with pytest.raises(SynthesisError, match="after 1 attempts"):
        synthesize("a mug next to a plate", SynthesisConfig(attempts=1), DirectorySink(tmp_path),
                   editor=make_editor(cfg))
    funnel = json.loads((tmp_path / "funnel.json").read_text())
    assert funnel[-1]["stage"] == "edit" and "blocked" in funnel[-1]["detail"]
    assert (tmp_path / "attempt-0" / "I_init.png").is_file()  # what was written before stays


def test_the_cli_with_an_llm_and_an_openai_image_endpoint(tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    from typer.testing import CliRunner

    from backends.fake_openai import FakeOpenAI
    from vcage.cli import app

    for var in ("VCAGE_LLM_MODEL", "VCAGE_IMAGE_MODEL", "VCAGE_LLM_BASE_URL", "VCAGE_IMAGE_BASE_URL"):
        monkeypatch.delenv(var, raising=False)
    with FakeOpenAI() as chat, FakeImagesOpenAI() as images:
        chat.script(*chat_replies())
        images.script(moderation_block(), lambda body: openai_image(body["files"]["image"][0]))
        out = tmp_path / "cli"
        result = CliRunner().invoke(app, [
            "synthesize", "a mug near a plate", "--out", str(out), "--no-reach", "--llm", "--llm-url",
            chat.base_url, "--llm-model", "fake-model", "--editor", "model", "--image-provider", "openai",
            "--image-url", images.base_url, "--image-model", "gpt-image-fake", "--image-field", "image"])
        assert result.exit_code == 0, result.output
        assert list(images.requests[0]["files"]) == ["image"] and len(images.requests) == 2
        edit = json.loads((out / "attempt-0" / "edit.json").read_text())
        assert [a["outcome"] for a in edit["answers"]] == ["blocked", "image"]
        images.script(moderation_block(), moderation_block(), moderation_block())
        chat.script(*chat_replies())
        result = CliRunner().invoke(app, [
            "synthesize", "a mug near a plate", "--out", str(tmp_path / "cli2"), "--no-reach", "--llm",
            "--llm-url", chat.base_url, "--llm-model", "fake-model", "--editor", "model", "--image-provider",
            "openai", "--image-url", images.base_url, "--image-model", "gpt-image-fake", "--attempts", "1"])
        assert result.exit_code == 2 and "moderation" in result.output, result.output
        result = CliRunner().invoke(app, [  # a model the server lacks: refused before anything is written
            "synthesize", "a mug near a plate", "--out", str(tmp_path / "cli3"), "--editor", "model",
            "--image-provider", "openai", "--image-url", images.base_url, "--image-model", "dall-e-9"])
        assert result.exit_code == 4 and "dall-e-9" in result.output, result.output
        assert not (tmp_path / "cli3").exists()


def chat_replies() -> list[str]:
    return ['{"objects": [{"type": "mug"}, {"type": "plate"}], "no_match": null}',
            json.dumps({"objects": [{"name": "mug", "type": "mug"}, {"name": "plate", "type": "plate"}],
                        "relations": [{"kind": "near", "a": "mug", "b": "plate"}],
                        "text": "A mug near a plate."})]
