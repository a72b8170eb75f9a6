"""``vcage train`` and ``vcage evaluate`` end to end: a generated dataset, a tiny training run, and
rollouts in the dataset's evaluation environment (only that the loop runs and reports its fields;
never a success figure)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from conftest import write_dataset
from vcage.cli import app
from vcage.policy.checkpoint import load_checkpoint

RUN = CliRunner()


def flat(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.slow
@pytest.mark.parametrize("policy", ["mlp", "diffusion"])
def test_train_then_evaluate_in_the_datasets_environment(generated: Path, tmp_path: Path,
                                                         policy: str) -> None:
    out = tmp_path / "run"
    args = ["train", str(generated), "--policy", policy, "--out", str(out), "--steps", "6",
            "--batch-size", "8", "--checkpoint-every", "3", "--threads", "1"]
    result = RUN.invoke(app, args)
    assert result.exit_code == 0, result.output
    text = flat(result.output)
    for field in ("steps", "final loss", "samples/s", "parameters", "checkpoint"):
        assert field in text
    again = RUN.invoke(app, args)
    assert again.exit_code == 2 and "--resume" in flat(again.output)
    resumed = RUN.invoke(app, [*args[:7], "8", *args[8:], "--resume"])
    assert resumed.exit_code == 0, resumed.output
    assert "6 -> 8" in flat(resumed.output)

    report = tmp_path / "eval.json"
    result = RUN.invoke(app, ["evaluate", str(out), "--episodes", "1", "--max-steps", "12", "--seed", "4",
                              "--json", str(report)])
    assert result.exit_code == 0, result.output
    text = flat(result.output)
    for field in ("success rate", "Wilson 95% interval", "subtask 1 done: the bell is pressed",
                  "rollouts/minute", "mean progress"):
        assert field in text
    record = json.loads(report.read_text())
    assert record["episodes"] == 1 and record["per_episode"][0]["steps"] <= 12
    assert record["checkpoint"].endswith("step-00000008.pt") and len(record["subtask_progress"]) == 1


def test_sizes_are_set_from_the_cli_and_an_exported_copy_evaluates(generated: Path, tmp_path: Path) -> None:
    out, moved = tmp_path / "run", tmp_path / "moved.pt"
    result = RUN.invoke(app, ["train", str(generated), "--out", str(out), "--steps", "2", "--batch-size", "4",
                              "--down-dims", "16,32", "--n-obs-steps", "4", "--obs-stride", "3",
                              "--threads", "1", "--export", str(moved), "--relative-objects"])
    assert result.exit_code == 0, result.output
    assert "exported for evaluation" in flat(result.output)
    copy = load_checkpoint(moved)
    assert tuple(copy["config"]["diffusion"]["down_dims"]) == (16, 32) and copy["evaluation_only"] is True
    assert copy["config"]["n_obs_steps"] == 4 and copy["config"]["obs_stride"] == 3
    assert copy["config"]["relative_objects"] is True  # and it evaluates on the offsets of the real scene
    evaluated = RUN.invoke(app, ["evaluate", str(moved), "--episodes", "1", "--max-steps", "8"])
    assert evaluated.exit_code == 0, evaluated.output
    bad = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "other"), "--down-dims", "16,x"])
    assert bad.exit_code == 2 and "comma-separated integers" in flat(bad.output)
    long = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "other"), "--n-obs-steps", "10"])
    assert long.exit_code == 2 and "must fit in the horizon 16" in flat(long.output)
    still = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "other"), "--obs-stride", "0"])
    assert still.exit_code == 2 and "--obs-stride" in flat(still.output)
    assert not (tmp_path / "other").exists()


def test_the_budget_can_be_given_in_passes_over_the_data(generated: Path, tmp_path: Path) -> None:
    from vcage.data import DatasetReader

    frames = DatasetReader(generated, videos=False).total_frames
    out = tmp_path / "run"
    result = RUN.invoke(app, ["train", str(generated), "--out", str(out), "--epochs", "0.05", "--batch-size",
                              "8", "--down-dims", "16,32", "--threads", "1"])
    assert result.exit_code == 0, result.output
    assert load_checkpoint(out)["step"] == math.ceil(0.05 * frames / 8) > 1
    assert "passes over the data" in flat(result.output)
    both = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "b"), "--epochs", "1",
                            "--steps", "5"])
    assert both.exit_code == 2 and "give one" in flat(both.output)
    none = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "b"), "--epochs", "0"])
    assert none.exit_code == 2 and "positive number of passes" in flat(none.output)
    assert not (tmp_path / "b").exists()


def test_bad_input_exits_2_with_the_reason(generated: Path, tmp_path: Path) -> None:
    missing = RUN.invoke(app, ["evaluate", str(tmp_path / "nothing"), "--episodes", "1"])
    assert missing.exit_code == 2 and missing.output.startswith("error:")
    assert "no checkpoint" in flat(missing.output)
    bare = write_dataset(tmp_path / "bare", 2, drop=("observation.ee_pose",))
    lacking = RUN.invoke(app, ["train", str(bare), "--out", str(tmp_path / "run")])
    assert lacking.exit_code == 2 and f"vcage backfill {bare}" in flat(lacking.output)
    wrong = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "run"), "--policy", "gpt"])
    assert wrong.exit_code == 2 and "valid: diffusion, mlp" in flat(wrong.output)
    graph = RUN.invoke(app, ["train", str(generated), "--out", str(tmp_path / "run"), "--cuda-graph"])
    assert graph.exit_code == 2 and "needs a CUDA device, not 'cpu'" in flat(graph.output)
    assert not (tmp_path / "run").exists()


def test_evaluate_on_the_training_scenes_rolls_out_the_datasets_own_scenes(generated: Path,
                                                                          tmp_path: Path) -> None:
    from vcage.data import DatasetReader

    out, report = tmp_path / "run", tmp_path / "eval.json"
    trained = RUN.invoke(app, ["train", str(generated), "--policy", "mlp", "--out", str(out), "--steps", "2",
                               "--batch-size", "8", "--threads", "1"])
    assert trained.exit_code == 0, trained.output
    assert load_checkpoint(out)["config"]["rotations"] == "rot6d"  # the default, when not chosen
    result = RUN.invoke(app, ["evaluate", str(out), "--episodes", "3", "--max-steps", "4",
                              "--training-scenes", "--json", str(report)])
    assert result.exit_code == 0, result.output
    text = flat(result.output)
    assert "the training dataset has 2 scenes" in text and "training (the dataset's own)" in text
    reader = DatasetReader(generated)
    record = json.loads(report.read_text())
    seeds = [e["scene_seed"] for e in record["per_episode"]]
    assert seeds == [reader.extras(i)["seed"] for i in range(2)]
    held_out = RUN.invoke(app, ["evaluate", str(out), "--episodes", "1", "--max-steps", "4", "--json",
                                str(report)])
    assert held_out.exit_code == 0, held_out.output
    first = json.loads(report.read_text())["per_episode"][0]["scene_seed"]
    assert first not in seeds
    # a fixed list of scenes, as the experiment keeps its held-out ones: episode k on the k-th
    chosen = tmp_path / "scenes.json"
    chosen.write_text(json.dumps({"tried": 3, "solved": [first, seeds[1]], "failed": [7]}))
    listed = RUN.invoke(app, ["evaluate", str(out), "--episodes", "3", "--max-steps", "4", "--scenes",
                              str(chosen), "--json", str(report)])
    assert listed.exit_code == 0, listed.output
    assert "(2 seeds)" in flat(listed.output) and "holds 2 scenes: evaluating on those" in flat(listed.output)
    assert [e["scene_seed"] for e in json.loads(report.read_text())["per_episode"]] == [first, seeds[1]]
    for bad in ("[]", "[-1]", '{"solved": "x"}', "not json"):
        chosen.write_text(bad)
        refused = RUN.invoke(app, ["evaluate", str(out), "--episodes", "1", "--scenes", str(chosen)])
        assert refused.exit_code == 2 and "--scenes" in flat(refused.output), bad
    both = RUN.invoke(app, ["evaluate", str(out), "--episodes", "1", "--scenes", str(report),
                            "--training-scenes"])
    assert both.exit_code == 2 and "give one" in flat(both.output)


def test_training_scenes_need_a_dataset_that_stores_its_seeds(tmp_path: Path) -> None:
    synthetic = write_dataset(tmp_path / "synthetic", 2)
    out = tmp_path / "run"
    assert RUN.invoke(app, ["train", str(synthetic), "--policy", "mlp", "--out", str(out), "--steps", "2",
                            "--batch-size", "8", "--threads", "1"]).exit_code == 0
    result = RUN.invoke(app, ["evaluate", str(out), "--episodes", "1", "--training-scenes"])
    assert result.exit_code == 2 and "does not store its episodes' scene seeds" in flat(result.output)


@pytest.mark.slow
def test_evaluate_with_temporal_ensembling_records_it_and_refuses_a_period_past_the_chunk(
        generated: Path, tmp_path: Path) -> None:
    out, report = tmp_path / "run", tmp_path / "eval.json"
    trained = RUN.invoke(app, ["train", str(generated), "--policy", "mlp", "--out", str(out), "--steps", "2",
                               "--batch-size", "8", "--threads", "1"])
    assert trained.exit_code == 0, trained.output
    base = ["evaluate", str(out), "--episodes", "2", "--max-steps", "6", "--batch", "2"]
    result = RUN.invoke(app, [*base, "--ensemble-every", "2", "--ensemble-decay", "0.1",
                              "--json", str(report)])
    assert result.exit_code == 0, result.output
    assert "a chunk every 2 steps, decay 0.1" in flat(result.output)
    record = json.loads(report.read_text())
    assert record["ensemble"] == {"every": 2, "decay": 0.1} and len(record["per_episode"]) == 2
    plain = RUN.invoke(app, [*base, "--json", str(report)])
    assert plain.exit_code == 0 and json.loads(report.read_text())["ensemble"] is None
    # a chunk runs 15 steps from the current frame
    refused = RUN.invoke(app, [*base, "--ensemble-every", "16"])
    assert refused.exit_code == 2 and "choose every <= 15" in flat(refused.output)
