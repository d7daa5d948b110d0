#!/usr/bin/env python3
"""ABI check of libdwivedi.so.1 against the committed baseline of the last release.

    check_abi.py check     --baseline B.abi --library libdwivedi.so --headers capi
    check_abi.py self-test --baseline B.abi --library libdwivedi.so --headers capi

`check` runs abidiff (Debian abigail-tools) on the baseline and the freshly built library and
accepts only compatible changes:
  - added functions and variables;
  - data members appended at the end of a struct that begins with uint32_t struct_size (the ABI
    rule of capi/dwivedi.h: callers set struct_size, the library reads only what they have), as
    long as no other public struct embeds it by value (then that struct's members move, which
    abidiff reports as offset changes and which is refused).
Everything else is refused: removed functions or variables (abidiff's exit bit 8,
ABIDIFF_ABI_INCOMPATIBLE_CHANGE), and any changed function or changed type (exit bit 4,
ABIDIFF_ABI_CHANGE, which abidiff also sets for harmless additions, so its report is read:
abidiff 2.2 sets bit 8 only for removed symbols, not for struct layout changes). It also checks
that the library exports only dwv_* functions declared in the public headers.

`self-test` shows that the check can fail: it plants incompatible changes into copies of the
baseline (a removed function, reordered struct members, a changed parameter type, a member
appended to a struct that another struct embeds) and one compatible change (a member appended to
a size-prefixed struct), and requires the right verdict for each, and for the true baseline.
Planting into the baseline is the same comparison as altering the build: abidiff compares two
descriptions, and which of them differs does not matter.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

ABIDIFF_ERROR, ABIDIFF_USAGE_ERROR, ABIDIFF_ABI_CHANGE, ABIDIFF_ABI_INCOMPATIBLE_CHANGE = 1, 2, 4, 8


def run_abidiff(baseline, library, headers):
    command = ["abidiff", "--leaf-changes-only", "--impacted-interfaces", "--headers-dir2", headers,
               "--drop-private-types", baseline, library]
    try:
        proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    except FileNotFoundError:
        sys.exit("check_abi.py: abidiff not found (Debian: apt-get install abigail-tools)")
    return proc.returncode, proc.stdout


def size_prefixed_structs(headers):
    """Names of the public structs whose first member is uint32_t struct_size."""
    names = set()
    for name in sorted(os.listdir(headers)):
        if name.endswith(".h"):
            with open(os.path.join(headers, name)) as f:
                text = f.read()
            names.update(re.findall(r"typedef\s+struct\s+(\w+)\s*\{\s*uint32_t\s+struct_size\s*;", text))
    return names


def declared_functions(headers):
    names = set()
    for name in sorted(os.listdir(headers)):
        if name.endswith(".h"):
            with open(os.path.join(headers, name)) as f:
                text = f.read()
            names.update(re.findall(r"\bDWV_API\b[^;(]*?\b(dwv_\w+)\s*\(", text))
    return names


def leaf_blocks(report):
    """Splits abidiff's leaf report into (header, body lines) of each changed leaf type."""
    blocks, current = [], None
    for line in report.splitlines():
        if line.startswith("'") and line.rstrip().endswith("changed:"):
            current = (line, [])
            blocks.append(current)
        elif current is not None and line.startswith(" "):
            current[1].append(line.strip())
        else:
            current = None
    return blocks


def verdict(rc, report, appendable):
    """(compatible, reasons) for one abidiff run."""
    reasons = []
    if rc & (ABIDIFF_ERROR | ABIDIFF_USAGE_ERROR):
        return False, ["abidiff failed (exit status %d)" % rc]
    if rc & ABIDIFF_ABI_INCOMPATIBLE_CHANGE:
        reasons.append("abidiff: incompatible change (a function or variable was removed)")
    for line in report.splitlines():
        if "summary:" not in line:
            continue
        for count, kind in re.findall(r"(\d+) (Removed|Changed)", line):
            if int(count) > 0:
                reasons.append("%s (%s)" % (line.strip(), kind.lower()))
    for header, body in leaf_blocks(report):
        m = re.match(r"'struct (\w+)", header)
        if not m or m.group(1) not in appendable:
            reasons.append("%s %s" % (header, " / ".join(body[:4])))
            continue
        old_size, ok, in_interfaces = None, True, False
        for line in body:
            size = re.match(r"type size changed from (\d+) to (\d+) \(in bits\)", line)
            member = re.match(r"'[^']*', at offset (\d+) \(in bits\)", line)
            if size:
                old_size = int(size.group(1))
            elif re.match(r"\d+ data member insertions?:", line):
                pass
            elif member:
                ok = ok and old_size is not None and int(member.group(1)) >= old_size
            elif re.match(r"(one|\d+) impacted interfaces?:", line):
                in_interfaces = True
            elif in_interfaces and re.match(r"(function|variable) ", line):
                pass
            elif line == "details were reported earlier":
                pass
            else:
                ok = False
        if not ok:
            reasons.append("%s %s" % (header, " / ".join(body[:4])))
    if rc & ABIDIFF_ABI_CHANGE and not reasons:
        pass  # only additions: compatible
    return not reasons, reasons


def exported_functions(library):
    out = subprocess.run(["nm", "-D", "--defined-only", library], stdout=subprocess.PIPE, check=True,
                         universal_newlines=True).stdout
    names = set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3:
            names.add(parts[2].split("@")[0])
    return names


def export_problems(exported, declared):
    """Exported names that are not dwv_* functions of the public headers (the version node aside)."""
    return sorted(n for n in exported if n != "DWIVEDI_1" and not (n.startswith("dwv_") and n in declared))


def check(args):
    rc, report = run_abidiff(args.baseline, args.library, args.headers)
    print(report)
    ok, reasons = verdict(rc, report, size_prefixed_structs(args.headers))
    stray = export_problems(exported_functions(args.library), declared_functions(args.headers))
    for name in stray:
        reasons.append("exported but not a dwv_* function of the public headers: %s" % name)
        ok = False
    print("abidiff exit status %d" % rc)
    if ok:
        print("ABI compatible with the baseline (additions only)")
        return 0
    print("ABI INCOMPATIBLE with the baseline %s:" % args.baseline)
    for r in reasons:
        print("  " + r)
    return 1


# ---- planted changes ------------------------------------------------------------------------------

def load(baseline):
    return ET.parse(baseline)


def struct(tree, name):
    for c in tree.iter("class-decl"):
        if c.get("name") == name:
            return c
    raise KeyError(name)


def members(decl):
    return [(dm, dm.find("var-decl").get("name")) for dm in decl.findall("data-member")]


def plant_removed_function(tree):
    """The baseline gains a function the library lacks: as if the library removed it."""
    symbols = tree.getroot().find("elf-function-symbols")
    original = next(s for s in symbols if s.get("name") == "dwv_hg_pdf")
    copy = ET.fromstring(ET.tostring(original))
    copy.set("name", "dwv_planted_removed")
    symbols.append(copy)
    for parent in tree.iter("abi-instr"):
        for f in list(parent):
            if f.tag == "function-decl" and f.get("name") == "dwv_hg_pdf":
                g = ET.fromstring(ET.tostring(f))
                g.set("name", "dwv_planted_removed")
                g.set("mangled-name", "dwv_planted_removed")
                g.set("elf-symbol-id", "dwv_planted_removed@@DWIVEDI_1")
                parent.append(g)
                return


def plant_reordered_members(tree):
    """dwv_medium_t's sigma_t and albedo swap places."""
    ms = dict((name, dm) for dm, name in members(struct(tree, "dwv_medium_t")))
    a, b = ms["sigma_t"].get("layout-offset-in-bits"), ms["albedo"].get("layout-offset-in-bits")
    ms["sigma_t"].set("layout-offset-in-bits", b)
    ms["albedo"].set("layout-offset-in-bits", a)


def plant_changed_parameter(tree):
    """dwv_exponential_sample's sigma was a float in the baseline."""
    float_id = next(t.get("id") for t in tree.iter("type-decl") if t.get("name") == "float")
    for f in tree.iter("function-decl"):
        if f.get("name") == "dwv_exponential_sample":
            f.find("parameter").set("type-id", float_id)
            return
    raise KeyError("dwv_exponential_sample")


def drop_last_member(decl):
    dm, _ = members(decl)[-1]
    offset = int(dm.get("layout-offset-in-bits"))
    decl.remove(dm)
    removed = int(decl.get("size-in-bits")) - offset
    decl.set("size-in-bits", str(offset))
    return offset, removed


def plant_appended_member(tree):
    """The baseline lacks dwv_estimate_result_t's last member: the library appended it (compatible)."""
    drop_last_member(struct(tree, "dwv_estimate_result_t"))


def plant_appended_embedded(tree):
    """The baseline lacks dwv_medium_t's last member, and dwv_estimate_options_t, which embeds a
    dwv_medium_t, is smaller by as much: the library appended to an embedded struct (incompatible)."""
    _, removed = drop_last_member(struct(tree, "dwv_medium_t"))
    options = struct(tree, "dwv_estimate_options_t")
    medium_offset = next(int(dm.get("layout-offset-in-bits")) for dm, n in members(options) if n == "medium")
    for dm, _ in members(options):
        offset = int(dm.get("layout-offset-in-bits"))
        if offset > medium_offset:
            dm.set("layout-offset-in-bits", str(offset - removed))
    options.set("size-in-bits", str(int(options.get("size-in-bits")) - removed))


PLANTS = [
    ("unaltered baseline", None, True),
    ("removed function", plant_removed_function, False),
    ("reordered struct members", plant_reordered_members, False),
    ("changed parameter type", plant_changed_parameter, False),
    ("member appended to a size-prefixed struct", plant_appended_member, True),
    ("member appended to a struct embedded in another", plant_appended_embedded, False),
]


def self_test(args):
    failures = 0
    appendable = size_prefixed_structs(args.headers)
    with tempfile.TemporaryDirectory() as scratch:
        for name, plant, expected in PLANTS:
            path = args.baseline
            if plant:
                tree = load(args.baseline)
                plant(tree)
                path = os.path.join(scratch, "planted.abi")
                tree.write(path)
            rc, report = run_abidiff(path, args.library, args.headers)
            ok, reasons = verdict(rc, report, appendable)
            good = ok == expected
            failures += not good
            print("%s: %s (abidiff exit %d, %s)%s" % (
                "ok  " if good else "FAIL", name, rc, "accepted" if ok else "refused",
                "" if good else "\n" + report))
            for r in reasons:
                print("        " + r)
    # The export rule, on names the library could export by mistake.
    declared = {"dwv_estimate", "dwv_walk_begin"}
    planted = {"dwv_estimate", "dwv_walk_begin", "dwv_fail", "cli_usage_error", "DWIVEDI_1"}
    stray = export_problems(planted, declared)
    good = stray == ["cli_usage_error", "dwv_fail"]
    failures += not good
    print("%s: stray exports found: %s" % ("ok  " if good else "FAIL", stray))
    print("%d planted cases, %d failed" % (len(PLANTS) + 1, failures))
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mode", choices=["check", "self-test"])
    parser.add_argument("--baseline", required=True)
    parser.add_argument("--library", required=True)
    parser.add_argument("--headers", required=True)
    args = parser.parse_args()
    return check(args) if args.mode == "check" else self_test(args)


if __name__ == "__main__":
    sys.exit(main())
