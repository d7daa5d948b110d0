"""A split bake for a render farm (docs/farm.md): chunks of sample indices, each one `dwivedi bake
--samples FIRST:COUNT` command, merged by one `dwivedi merge` when all are done.

    python3 -m dwivedi.farm SCENE.json --spp 256 --chunks 8 --out FOLDER [--seed 7] [--name shot]

writes into FOLDER (scripts are written under temporary names and renamed into place):

  farm.json      the plan: scene, total samples, seed, every chunk's range and part file
  chunks.txt     one shell command a chunk, line i for chunk i (for any farm manager that runs one
                 command per task: Flamenco, Deadline, OpenCue; docs/farm.md)
  merge.txt      the merge command, to run when every chunk succeeded
  run-chunk.sh   `run-chunk.sh N` runs line N + 1 of chunks.txt in FOLDER (Deadline's <STARTFRAME>,
                 OpenCue's #IFRAME#)
  bake.sbatch    Slurm: the chunks as one job array (task i bakes chunk i)
  merge.sbatch   Slurm: the merge
  submit.sh      Slurm: submits both, the merge with --dependency=afterok on the array (it never
                 runs if a chunk fails) and --kill-on-invalid-dep (it is cancelled, not left pending);
                 `submit.sh --wait` waits and says which chunk failed

Every command runs in FOLDER (the scripts `cd` there / Slurm's --chdir), and every path in them is
relative to it unless the scene lies outside it: the folder can be moved to the farm's shared
storage as a whole. Chunks write parts/chunk-I.dwvpart, logs go to logs/, the merge writes
NAME.exr, NAME.png and NAME.json. The dwivedi program is `dwivedi` on the nodes' PATH unless
--dwivedi names another; the Slurm scripts take $DWIVEDI from the submitting shell first.

Standard library only; nothing here loads libdwivedi (the add-on calls `plan` and `write_plan`).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import sys
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

PLAN_FILE = "farm.json"
PLAN_FORMAT = "dwivedi-farm-plan"
PLAN_VERSION = 1
MAX_SAMPLES = 1 << 24  # dwv_bake_options_t.samples' upper bound (capi/dwivedi.h)

# `dwivedi bake` flags a plan may pass to every chunk (src/cli/bake.c), and the display flags the
# merge takes (`dwivedi merge --help`). --threads goes to the chunks only; --samples, --time,
# --error and --out are the plan's own.
BAKE_FLAGS = ("--technique", "--channel-walks", "--width", "--height", "--threads")
DISPLAY_FLAGS = ("--ocio", "--display", "--view", "--look", "--exposure", "--gamma")


class PlanError(ValueError):
    """A plan that cannot be made as asked; the message says why."""


@dataclass
class Chunk:
    index: int
    first: int
    count: int

    @property
    def part(self) -> str:
        """The chunk's part file, relative to the plan's folder."""
        return f"parts/chunk-{self.index}.dwvpart"

    @property
    def samples(self) -> str:
        return f"{self.first}:{self.count}"


@dataclass
class Plan:
    """A split bake: `scene` (a path as the commands name it), `spp` samples per pixel in all,
    cut into `chunks`; `name` is the merged output's prefix. seed None: the scene file's."""

    scene: str
    spp: int
    chunks: List[Chunk]
    name: str
    seed: Optional[int] = None
    dwivedi: str = "dwivedi"
    bake_args: List[str] = field(default_factory=list)
    merge_args: List[str] = field(default_factory=list)
    cpus_per_task: int = 1
    partition: Optional[str] = None
    time_limit: Optional[str] = None

    def chunk_args(self, chunk: Chunk) -> List[str]:
        """argv of chunk `chunk`'s bake, run in the plan's folder."""
        args = [self.dwivedi, "bake", self.scene, "--spp", str(self.spp)]
        if self.seed is not None:
            args += ["--seed", str(self.seed)]
        return args + self.bake_args + ["--samples", chunk.samples, "--out", chunk.part[:-len(".dwvpart")], "--quiet"]

    def merge_argv(self) -> List[str]:
        """argv of the merge, run in the plan's folder."""
        return [self.dwivedi, "merge", *[c.part for c in self.chunks], "--out", self.name, *self.merge_args]


def split_samples(spp: int, chunks: int) -> List[Chunk]:
    """`spp` sample indices cut into `chunks` ranges in order, sizes differing by at most one."""
    if isinstance(spp, bool) or not isinstance(spp, int) or not 1 <= spp <= MAX_SAMPLES:
        raise PlanError(f"--spp must be a whole number from 1 to {MAX_SAMPLES}, not {spp!r}")
    if isinstance(chunks, bool) or not isinstance(chunks, int) or not 1 <= chunks <= spp:
        raise PlanError(f"--chunks must be a whole number from 1 to the samples per pixel ({spp}), not {chunks!r}")
    base, extra = divmod(spp, chunks)
    out, first = [], 0
    for i in range(chunks):
        count = base + (1 if i < extra else 0)
        out.append(Chunk(i, first, count))
        first += count
    return out


def _check_flags(args: Sequence[str], allowed: Sequence[str], what: str) -> List[str]:
    """`args` as FLAG VALUE pairs, each FLAG one of `allowed`."""
    args = list(args)
    if len(args) % 2:
        raise PlanError(f"{what}: '{args[-1]}' has no value")
    for flag, value in zip(args[0::2], args[1::2]):
        if flag not in allowed:
            raise PlanError(f"{what}: '{flag}' is not one of {', '.join(allowed)}")
        if value == "" or "\n" in value or "\0" in value:
            raise PlanError(f"{what}: {flag} has an empty or multi-line value")
    return args


def _check_name(name: str) -> str:
    """`name` if it is a file name that needs no quoting in a script or a Slurm job name."""
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]{0,99}", name):
        raise PlanError(f"the output name {name!r} must be letters, digits, '.', '_' or '-' (no folders)")
    return name


def plan(scene: str, spp: int, chunks: int, folder: str, *, name: Optional[str] = None, seed: Optional[int] = None,
         dwivedi: str = "dwivedi", bake_args: Sequence[str] = (), merge_args: Sequence[str] = (),
         cpus_per_task: int = 1, partition: Optional[str] = None, time_limit: Optional[str] = None) -> Plan:
    """The plan of `scene` (a scene file; must exist) baked at `spp` in `chunks` chunks, to be
    written into `folder`. The scene is named relative to the folder when it lies inside it."""
    if not os.path.isfile(scene):
        raise PlanError(f"no scene file '{scene}'")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 1 << 64):
        raise PlanError(f"--seed must be a whole number from 0 to 2^64 - 1, not {seed!r}")
    if isinstance(cpus_per_task, bool) or not isinstance(cpus_per_task, int) or not 1 <= cpus_per_task <= 1024:
        raise PlanError(f"--cpus-per-task must be from 1 to 1024, not {cpus_per_task!r}")
    for what, value in (("--partition", partition), ("--time-limit", time_limit)):
        if value is not None and (not value or any(c.isspace() for c in value)):
            raise PlanError(f"{what}: {value!r} is empty or holds white space")
    if not dwivedi or "\n" in dwivedi:
        raise PlanError("--dwivedi: the program is empty or multi-line")
    scene_abs = os.path.abspath(scene)
    folder_abs = os.path.abspath(folder)
    inside = os.path.commonpath([scene_abs, folder_abs]) == folder_abs
    shown = os.path.relpath(scene_abs, folder_abs) if inside else scene_abs
    if "\n" in shown:
        raise PlanError("the scene's path holds a line break")
    stem = os.path.splitext(os.path.basename(scene))[0]
    outputs = lambda n: {os.path.join(folder_abs, n + suffix) for suffix in (".exr", ".png", ".json")}  # noqa: E731
    if name is None:
        name = stem if scene_abs not in outputs(stem) else stem + "_merged"
    if scene_abs in outputs(_check_name(name)):
        raise PlanError(f"the merge's {name}.json would replace the scene file: choose another output name")
    return Plan(scene=shown, spp=spp, chunks=split_samples(spp, chunks), name=name, seed=seed,
                dwivedi=dwivedi, bake_args=_check_flags(bake_args, BAKE_FLAGS, "bake options"),
                merge_args=_check_flags(merge_args, DISPLAY_FLAGS, "merge options"),
                cpus_per_task=cpus_per_task, partition=partition, time_limit=time_limit)


def _command(argv: Sequence[str]) -> str:
    return " ".join(shlex.quote(a) for a in argv)


def _program_line(plan: Plan) -> str:
    """The scripts' dwivedi program: $DWIVEDI from the submitting shell, else the plan's (quoted
    for the shell: an assignment's word is not split, and its quotes are removed)."""
    return f"dwivedi=${{DWIVEDI:-{shlex.quote(plan.dwivedi)}}}"


def _slurm_header(plan: Plan, job: str, log: str) -> List[str]:
    lines = ["#!/bin/bash", f"#SBATCH --job-name={plan.name}-{job}", f"#SBATCH --output=logs/{log}.out",
             f"#SBATCH --error=logs/{log}.err"]
    if plan.partition:
        lines.append(f"#SBATCH --partition={plan.partition}")
    if plan.time_limit:
        lines.append(f"#SBATCH --time={plan.time_limit}")
    return lines


def bake_sbatch(plan: Plan) -> str:
    """The chunks' job array: task i bakes chunk i; a failed chunk writes logs/chunk-I.failed."""
    last = len(plan.chunks) - 1
    lines = _slurm_header(plan, "chunks", "chunk-%a")
    lines += [f"#SBATCH --array=0-{last}", f"#SBATCH --cpus-per-task={plan.cpus_per_task}",
              "# Written by `python3 -m dwivedi.farm` (docs/farm.md); submit with submit.sh, which runs it in its folder.",
              "set -u", _program_line(plan),
              'i="${SLURM_ARRAY_TASK_ID:?not run as a Slurm array task}"', 'case "$i" in']
    for c in plan.chunks:
        lines.append(f"  {c.index}) command=({_command(plan.chunk_args(c)[1:])}) ;;")
    lines += [f'  *) echo "dwivedi farm: no chunk $i in this plan (0 to {last})" >&2; exit 2 ;;', "esac"]
    if "--threads" not in plan.bake_args:  # the cores Slurm gave the task; the image does not depend on it
        lines.append('command+=(--threads "${SLURM_CPUS_PER_TASK:-1}")')
    lines += ['mkdir -p parts logs', 'rm -f "logs/chunk-$i.failed"',
              '"$dwivedi" "${command[@]}"', "status=$?",
              'if [ "$status" -ne 0 ]; then',
              '  echo "dwivedi farm: chunk $i (${command[*]}) failed with exit status $status; '
              'the merge will not run (see logs/chunk-$i.err)" | tee "logs/chunk-$i.failed" >&2', "fi",
              'exit "$status"', ""]
    return "\n".join(lines)


def merge_sbatch(plan: Plan) -> str:
    """The merge job; it records its exit status in logs/merge.status."""
    lines = _slurm_header(plan, "merge", "merge")
    lines += ["#SBATCH --cpus-per-task=1", "# Written by `python3 -m dwivedi.farm` (docs/farm.md).", "set -u",
              _program_line(plan),
              f'"$dwivedi" {_command(plan.merge_argv()[1:])}', "status=$?",
              'echo "$status" > logs/merge.status', 'exit "$status"', ""]
    return "\n".join(lines)


def submit_sh(plan: Plan) -> str:
    parts = " ".join(shlex.quote(c.part) for c in plan.chunks)
    return "\n".join([
        "#!/bin/bash",
        f"# Submits the {len(plan.chunks)} chunks of {plan.name} as one Slurm job array and its merge as a job that",
        "# runs only when every chunk succeeded (written by `python3 -m dwivedi.farm`; docs/farm.md).",
        "# --wait: wait for the merge; exit 0 when it wrote its outputs, else 1 with the failed chunks.",
        "set -euo pipefail",
        'cd "$(dirname "$0")"',
        'wait_for_merge=0',
        'if [ "${1:-}" = "--wait" ]; then wait_for_merge=1; elif [ $# -gt 0 ]; then',
        '  echo "usage: $0 [--wait]" >&2; exit 2; fi',
        "mkdir -p parts logs",
        "rm -f logs/chunk-*.failed logs/merge.status",
        'chunks=$(sbatch --parsable --chdir="$PWD" bake.sbatch)',
        'chunks="${chunks%%;*}"',
        'merge_flags=(--parsable --chdir="$PWD" --dependency="afterok:$chunks" --kill-on-invalid-dep=yes)',
        f'echo "dwivedi farm: {len(plan.chunks)} chunks are job array $chunks; the merge runs after all of them"',
        'if [ "$wait_for_merge" -eq 0 ]; then',
        '  merge=$(sbatch "${merge_flags[@]}" merge.sbatch)',
        '  echo "dwivedi farm: the merge is job ${merge%%;*} (writes ' + plan.name + '.exr, .png, .json)"',
        "  exit 0", "fi",
        'sbatch --wait "${merge_flags[@]}" merge.sbatch >/dev/null || true',
        'if [ "$(cat logs/merge.status 2>/dev/null)" = 0 ]; then',
        f'  echo "dwivedi farm: merged: {plan.name}.exr, {plan.name}.png, {plan.name}.json"; exit 0; fi',
        'if [ -f logs/merge.status ]; then',
        '  echo "dwivedi farm: the merge failed: $(tail -n 1 logs/merge.err)" >&2; exit 1; fi',
        'echo "dwivedi farm: the merge did not run: a chunk failed" >&2',
        "cat logs/chunk-*.failed >&2 2>/dev/null || true",
        f"for part in {parts}; do",
        '  [ -f "$part" ] || echo "dwivedi farm: $part was not written (see logs/$(basename "$part" .dwvpart).err)" >&2',
        "done",
        "exit 1", ""])


def run_chunk_sh(plan: Plan) -> str:
    """Runs chunk N of the plan (line N + 1 of chunks.txt) in its folder: for farm managers that
    give each task a number (Deadline's <STARTFRAME>, OpenCue's #IFRAME#)."""
    count = len(plan.chunks)
    return "\n".join([
        "#!/bin/bash",
        f"# Runs chunk N (0 to {count - 1}) of this plan, line N + 1 of chunks.txt, in this folder",
        "# (written by `python3 -m dwivedi.farm`; docs/farm.md).",
        "set -euo pipefail",
        'cd "$(dirname "$0")"',
        'n="${1:-}"',
        f'case "$n" in ""|*[!0-9]*) echo "run-chunk.sh: \'$n\' is not a chunk number (0 to {count - 1})" >&2; exit 2 ;; esac',
        f'if [ "$n" -ge {count} ]; then echo "run-chunk.sh: no chunk $n (0 to {count - 1})" >&2; exit 2; fi',
        'mkdir -p parts',
        'exec bash -c "$(sed -n "$((n + 1))p" chunks.txt)"', ""])


def plan_json(plan: Plan) -> Dict[str, object]:
    return {"format": PLAN_FORMAT, "version": PLAN_VERSION, "scene": plan.scene, "spp": plan.spp, "seed": plan.seed,
            "name": plan.name, "bake_args": plan.bake_args, "merge_args": plan.merge_args,
            "chunks": [{"index": c.index, "first": c.first, "count": c.count, "part": c.part} for c in plan.chunks]}


def read_plan_parts(folder: str) -> Tuple[List[str], str]:
    """(part files, output name) of the plan in `folder` (its farm.json), paths joined to the
    folder; PlanError if there is no readable plan there."""
    path = os.path.join(folder, PLAN_FILE)
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        raise PlanError(f"cannot read the plan '{path}': {e}") from e
    if not isinstance(data, dict) or data.get("format") != PLAN_FORMAT or data.get("version") != PLAN_VERSION:
        raise PlanError(f"'{path}' is not a dwivedi farm plan (version {PLAN_VERSION})")
    try:
        parts = [os.path.join(folder, c["part"]) for c in data["chunks"]]
        name = _check_name(data["name"])
    except (KeyError, TypeError) as e:
        raise PlanError(f"'{path}' lacks its chunks or name ({e})") from e
    return parts, name


def _write_atomic(path: str, text: str, executable: bool = False) -> None:
    temporary = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.{os.getpid()}.tmp")
    try:
        with open(temporary, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        os.chmod(temporary, 0o755 if executable else 0o644)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


def write_plan(plan: Plan, folder: str) -> List[str]:
    """Writes the plan's files into `folder` (made if needed); returns their paths."""
    os.makedirs(os.path.join(folder, "parts"), exist_ok=True)
    os.makedirs(os.path.join(folder, "logs"), exist_ok=True)
    files = [
        (PLAN_FILE, json.dumps(plan_json(plan), indent=1) + "\n", False),
        ("chunks.txt", "".join(_command(plan.chunk_args(c)) + "\n" for c in plan.chunks), False),
        ("merge.txt", _command(plan.merge_argv()) + "\n", False),
        ("bake.sbatch", bake_sbatch(plan), False),
        ("merge.sbatch", merge_sbatch(plan), False),
        ("submit.sh", submit_sh(plan), True),
        ("run-chunk.sh", run_chunk_sh(plan), True),
    ]
    written = []
    for name, text, executable in files:
        path = os.path.join(folder, name)
        _write_atomic(path, text, executable)
        written.append(path)
    return written


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m dwivedi.farm", description=(
        "Writes a split bake for a farm: chunk commands, a Slurm job array and its merge (docs/farm.md)."))
    parser.add_argument("scene", help="the scene file (docs/scene-format.md)")
    parser.add_argument("--spp", type=int, required=True, help="samples per pixel in all")
    parser.add_argument("--chunks", type=int, required=True, help="how many chunks (1 to --spp)")
    parser.add_argument("--out", required=True, metavar="FOLDER", help="where the plan, parts and result go")
    parser.add_argument("--name", help="the merged output's name (default: the scene file's)")
    parser.add_argument("--seed", type=int, help="random seed (default: the scene file's)")
    parser.add_argument("--dwivedi", default="dwivedi", metavar="PROGRAM", help="the dwivedi program on the nodes")
    parser.add_argument("--cpus-per-task", type=int, default=1, help="Slurm: cores a chunk takes (its --threads)")
    parser.add_argument("--partition", help="Slurm partition")
    parser.add_argument("--time-limit", help="Slurm --time of every job (e.g. 2:00:00)")
    for flag in BAKE_FLAGS + DISPLAY_FLAGS:
        parser.add_argument(flag, dest="pass_" + flag[2:].replace("-", "_"), metavar="VALUE",
                            help="passed to every chunk's bake" if flag in BAKE_FLAGS else "passed to the merge")
    args = parser.parse_args(argv)

    def passed(flags: Sequence[str]) -> List[str]:
        out: List[str] = []
        for flag in flags:
            value = getattr(args, "pass_" + flag[2:].replace("-", "_"))
            if value is not None:
                out += [flag, value]
        return out

    try:
        made = plan(args.scene, args.spp, args.chunks, args.out, name=args.name, seed=args.seed, dwivedi=args.dwivedi,
                    bake_args=passed(BAKE_FLAGS), merge_args=passed(DISPLAY_FLAGS), cpus_per_task=args.cpus_per_task,
                    partition=args.partition, time_limit=args.time_limit)
        write_plan(made, args.out)
    except (PlanError, OSError) as e:
        print(f"dwivedi.farm: {e}", file=sys.stderr)
        return 1
    sizes = ", ".join(c.samples for c in made.chunks[:4]) + (", ..." if len(made.chunks) > 4 else "")
    print(f"dwivedi.farm: {len(made.chunks)} chunks ({sizes}) of {made.spp} spp in {args.out}: "
          f"chunks.txt + merge.txt, or Slurm: {os.path.join(args.out, 'submit.sh')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
