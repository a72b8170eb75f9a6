"""The dataset card, ``README.md`` at a dataset's root: what made the dataset and what its files hold.

Plain Markdown (with the small YAML header the Hugging Face Hub reads), written from
``meta/info.json``'s content and the task list at each commit, so it always describes the committed
episodes. Nothing here touches the network.
"""

from __future__ import annotations

from typing import Any

from vcage.data import layout

PROVENANCE_TEXT = {"vcage/seed": "the seed the episode's attempt ran with (replays it exactly)",
                   "vcage/attempt": "which attempt of its episode was accepted (0 = the first)",
                   "vcage/oracle_success": "whether the simulator's oracle confirmed every subtask"}


def _cell(value: Any) -> str:
    text = "" if value is None else str(value)
    return text.replace("|", "\\|").replace("\n", " ")


def _names(names: Any) -> str:
    if isinstance(names, dict):
        names = next((v for v in names.values() if isinstance(v, list)), None)
    if not names:
        return "-"
    return ", ".join(f"`{_cell(n)}`" for n in names)


def dataset_card(info: dict[str, Any], tasks: list[str]) -> str:
    """The card for a dataset whose ``meta/info.json`` holds ``info`` and whose tasks are ``tasks``."""
    episodes, frames, fps = int(info["total_episodes"]), int(info["total_frames"]), int(info["fps"])
    features = info.get("features", {})
    cameras = {k: f for k, f in features.items() if f.get("dtype") == "video"}
    minutes = frames / fps / 60 if fps else 0.0
    lines = [
        "---",
        "tags:",
        "- LeRobot",
        "- vcage",
        "- robotics",
        "- simulation",
        "configs:",
        "- config_name: default",
        "  data_files: data/*/*.parquet",
        "---",
        "",
        "# vcage dataset",
        "",
        "Robot-manipulation episodes generated in MuJoCo by **vcage**, which plans each instruction, "
        "runs the plan in randomised scenes, and keeps an episode only when its subtasks are verified. "
        f"Layout: LeRobot {info.get('codebase_version', layout.CODEBASE_VERSION)}.",
        "",
        f"- robot: `{_cell(info.get('robot_type'))}`",
        f"- episodes: {episodes}",
        f"- frames: {frames} at {fps} fps ({minutes:.1f} minutes)",
        f"- tasks (instructions): {len(tasks)}",
        "",
    ]
    lines += [f"  {i}. {_cell(task)}" for i, task in enumerate(tasks)] + [""]
    lines += ["## Features", "", "| feature | dtype | shape | names |", "|---|---|---|---|"]
    for key, ft in features.items():
        shape = "×".join(str(s) for s in ft.get("shape") or [])
        lines.append(f"| `{_cell(key)}` | {_cell(ft.get('dtype'))} | {shape} | {_names(ft.get('names'))} |")
    lines += ["", "## Cameras", ""]
    if cameras:
        lines += ["| camera | height × width | codec | pixel format |", "|---|---|---|---|"]
        for key, ft in cameras.items():
            vinfo = ft.get("info") or {}
            h, w = (ft.get("shape") or [None, None])[:2]
            lines.append(f"| `{_cell(key)}` | {h} × {w} | {_cell(vinfo.get('video.codec'))} | "
                         f"{_cell(vinfo.get('video.pix_fmt'))} |")
    else:
        lines.append("None: the episodes hold no video.")
    lines += [
        "",
        "## Files",
        "",
        f"- `{layout.DATA_PATH}`: the frames of an episode (features, timestamp, indices, task index).",
        f"- `{layout.VIDEO_PATH}`: one MP4 per camera and episode.",
        f"- `{layout.INFO_PATH}`: features, fps, totals; rewritten last, it commits each episode.",
        f"- `{layout.EPISODES_PATH}`: one row per episode: length, index range, file locations, "
        "per-episode statistics and vcage's provenance columns.",
        f"- `{layout.TASKS_PATH}`: the task strings, by task index.",
        f"- `{layout.STATS_PATH}`: statistics of every feature over all episodes.",
        "",
        "vcage's own files (LeRobot ignores them):",
        "",
        f"- `{layout.VCAGE_PATH}`: the format marker, the schema of vcage's additions (2: every episode row "
        "holds the SHA-256 content digests of its files, `vcage/sha256/*`) and the configuration the "
        "dataset was made with; appending needs the same configuration.",
        f"- `{layout.ATTEMPTS_LOG}`: every attempt, accepted or not, with its stage, reason and "
        "oracle audit.",
        f"- `{layout.RUNS_LOG}`: one line per generation run: its funnel (attempts by stage, time) and the "
        "software its episodes depend on: versions, the git commit, a digest of vcage's files and the lock "
        "file's hash (the same seed gives the same episode under them).",
        f"- `{layout.EXTRAS_PATH.format(episode_index=0).replace('000000', 'NNNNNN')}`: an episode's "
        "seed, plan, scene, critic verdicts, oracle audit and software.",
        f"- `{layout.ARRAYS_PATH.format(episode_index=0).replace('000000', 'NNNNNN')}`: the simulator "
        "states of an episode, for exact replay.",
        f"- `{layout.CARD_PATH}`: this card, rewritten at each commit.",
        "",
        "Provenance columns of the episodes metadata (empty where unknown):",
        "",
    ]
    lines += [f"- `{column}`: {text}" for column, text in PROVENANCE_TEXT.items()]
    lines += ["", "Check the files with `vcage verify <dataset>`; `--repair` drops a damaged tail.", ""]
    return "\n".join(lines)
