"""Running the `dwivedi` command (src/cli) in the CLI tests, and the contracts every verb keeps: --json
writes one line holding one JSON object, and bad usage exits 2 with nothing on stdout and one line
on stderr.

ctest sets DWIVEDI_CLI (see tests/CMakeLists.txt). Standard library only.
"""
import json
import os
import subprocess
import unittest
from typing import Dict, Iterable, List, Set

USAGE = 2  # exit code of bad usage (src/cli/cli.h)


def run_cli(*args: str) -> subprocess.CompletedProcess:
    cli = os.environ.get("DWIVEDI_CLI")
    if not cli:
        raise AssertionError("DWIVEDI_CLI is not set; run these tests through ctest")
    return subprocess.run([cli, *args], capture_output=True, text=True, timeout=60)


def run_json(test: unittest.TestCase, keys: Set[str], *args: str) -> Dict[str, object]:
    """The object that `dwivedi args --json` writes, after `test` has checked that the run succeeded
    with nothing on stderr and wrote one line: a JSON object with exactly `keys`."""
    done = run_cli(*args, "--json")
    test.assertEqual(done.returncode, 0, done.stderr)
    test.assertEqual(done.stderr, "")
    test.assertEqual(len(done.stdout.splitlines()), 1, done.stdout)
    result = json.loads(done.stdout)
    test.assertIsInstance(result, dict)
    test.assertEqual(set(result), keys)
    return result


def listed_verbs(help_text: str) -> List[str]:
    """The verbs that `dwivedi --help` lists: the first word of each line after "verbs:", up to the
    first empty line."""
    lines = help_text.splitlines()
    verb_lines = lines[lines.index("verbs:") + 1:]
    return [line.split()[0] for line in verb_lines[:verb_lines.index("")]]


def assert_bad_usage(test: unittest.TestCase, args: List[str], start: str, words: Iterable[str]) -> None:
    """`dwivedi args` exits 2, writes nothing on stdout and one line on stderr that begins with
    `start` and contains every one of `words`."""
    done = run_cli(*args)
    test.assertEqual(done.returncode, USAGE, (args, done.stdout, done.stderr))
    test.assertEqual(done.stdout, "")
    test.assertTrue(done.stderr.endswith("\n"), repr(done.stderr))
    lines = done.stderr.splitlines()
    test.assertEqual(len(lines), 1, done.stderr)
    test.assertTrue(lines[0].startswith(start), lines[0])
    for word in words:
        test.assertIn(word, lines[0])
