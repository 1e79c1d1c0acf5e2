"""A class graded in shards: ``check DIR --shard K/N`` on each machine, ``check merge`` of their JSON.

The merged reports are the reports one run writes (timings aside), the same
files found again across shards; the shard of a name is the same on every
machine (a stable hash, not Python's per-process ``hash``).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from support import assert_user_error, run_cli

from glsandbox.errors import SandboxError
from glsandbox.grading.shards import in_shard, parse_shard, shard_of

RIGHT = 'name = "cube"\n[camera]\neye = [2, 1.5, 3]\n[[nodes]]\nmesh = "cube"\n'
WRONG = RIGHT.replace('mesh = "cube"', 'mesh = "sphere"')
RUBRIC = """[[check]]
name = "still"
golden = "still.png"
size = "48x36"

[[check]]
name = "late"
golden = "late.png"
set = ["time=1"]
size = "40x30"
points = 2
hidden = true
"""


def without_timings(report: dict) -> dict:
    def strip(value):
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if k != "seconds"}
        if isinstance(value, list):
            return [strip(v) for v in value]
        return value
    return strip(report)


def test_the_shard_of_a_name_is_a_stable_hash_and_every_name_has_one() -> None:
    names = [f"student_{n:03d}" for n in range(200)]
    for count in (1, 2, 3, 8):
        owners = [[k for k in range(1, count + 1) if in_shard(name, (k, count))] for name in names]
        assert all(len(o) == 1 for o in owners)  # each in exactly one shard
        sizes = [sum(o == [k] for o in owners) for k in range(1, count + 1)]
        assert min(sizes) > 200 / count / 2  # none starved
    # another interpreter (another PYTHONHASHSEED) gives the same shards
    code = "from glsandbox.grading.shards import shard_of; print([shard_of(f'student_{n:03d}', 7) for n in range(50)])"
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env={"PYTHONHASHSEED": "12345", "PATH": ""})
    assert other.stdout.strip() == str([shard_of(f"student_{n:03d}", 7) for n in range(50)])
    assert parse_shard("2/8") == (2, 8)
    for bad in ("0/2", "3/2", "2", "a/b", "1/0", ""):
        with pytest.raises(SandboxError, match="--shard"):
            parse_shard(bad)


@pytest.mark.slow
def test_shards_merged_are_one_run(tmp_path: Path, gl) -> None:
    (tmp_path / "model.toml").write_text(RIGHT)
    rubric = tmp_path / "grading.toml"
    rubric.write_text(RUBRIC)
    assert run_cli("check", str(tmp_path / "model.toml"), "--rubric", str(rubric), "--update").returncode == 0
    subs = tmp_path / "subs"
    subs.mkdir()
    for n in range(8):
        (subs / f"s{n}.toml").write_text(WRONG if n % 3 == 0 else RIGHT + f"# {n}\n")
    (subs / "copy_a.toml").write_text(RIGHT)
    (subs / "copy_b.toml").write_text(RIGHT)  # the same files as copy_a, whichever shards they fall in
    (subs / "broken.toml").write_text("[[nodes]\n")
    out = tmp_path / "out"
    one = run_cli("check", str(subs), "--rubric", str(rubric), "--json", str(out / "one.json"), "--csv",
                  str(out / "one.csv"))
    assert one.returncode == 1
    shards = []
    for k in (1, 2):
        path = out / f"shard{k}.json"
        proc = run_cli("check", str(subs), "--rubric", str(rubric), "--shard", f"{k}/2", "--json", str(path))
        assert proc.returncode in (0, 1), proc.stderr
        shards.append(path)
    parts = [json.loads(p.read_text())["submissions"] for p in shards]
    assert parts[0] and parts[1] and len(parts[0]) + len(parts[1]) == 11
    merged = run_cli("check", "merge", *map(str, shards), "--rubric", str(rubric), "--json", str(out / "merged.json"),
                     "--csv", str(out / "merged.csv"), "--html", str(out / "merged.html"), "--junit",
                     str(out / "merged.xml"), "--gradescope", str(out / "merged-gs.json"))
    assert merged.returncode == 1, merged.stderr
    whole = json.loads((out / "one.json").read_text())
    again = json.loads((out / "merged.json").read_text())
    assert without_timings(again) == without_timings(whole)
    copies = {s["name"]: s["same_as"] for s in again["submissions"] if s["name"].startswith("copy")}
    assert copies == {"copy_a": ["copy_b"], "copy_b": ["copy_a"]}
    assert "same files: copy_a = copy_b" in merged.stdout
    one_csv = [line.rsplit(",", 2)[0] for line in (out / "one.csv").read_text().splitlines()]
    merged_csv = [line.rsplit(",", 2)[0] for line in (out / "merged.csv").read_text().splitlines()]
    assert one_csv == merged_csv  # the same rows, the seconds and error columns at the end aside
    # a shard's report given twice, a report of another grading file, not a report: one line each
    assert_user_error(run_cli("check", "merge", str(shards[0]), str(shards[0]), "--rubric", str(rubric)),
                      "is in", "too")
    assert_user_error(run_cli("check", "merge", str(shards[0]), "--golden", str(tmp_path / "still.png")),
                      "graded with")
    (out / "junk.json").write_text("[1, 2]")
    assert_user_error(run_cli("check", "merge", str(out / "junk.json"), "--rubric", str(rubric)),
                      "junk.json", "not a report")
    assert_user_error(run_cli("check", str(subs), "--rubric", str(rubric), "--shard", "3/2"), "--shard '3/2'")
