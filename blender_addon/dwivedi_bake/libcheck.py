"""Checks of a libdwivedi file before the add-on loads it, each with a message a user can act on.

Standard library only and no bpy, so that it runs (and is tested) outside Blender too. In order:

1. the file is there and is a regular file;
2. it is an ELF shared object (magic, type), not damaged: its header, program and section header
   tables and loadable segments all lie inside the file (a truncated download or copy fails here);
3. it is built for the CPU and word size this Blender runs on (read from the ELF header of the
   running process, /proc/self/exe, so a 32-bit Blender on a 64-bit kernel is judged right);
4. its SONAME is libdwivedi.so.N with N the ABI generation the shim is written for (older:
   "too old", newer: "too new") and it defines every function the shim declares (a library that
   lacks some is too old for this add-on);
5. then the caller loads it (dlopen through ctypes), where the dynamic loader's own message, for
   instance a missing dependency, becomes the problem.

check_file() returns a Problem or None; nothing here raises for a bad file.
"""
from __future__ import annotations

import os
import platform
import struct
from typing import Dict, Iterable, List, Optional, Tuple

# e_machine values (the ELF gABI's registry) and the names people know them by.
MACHINES: Dict[int, str] = {
    3: "x86 (i386)", 8: "MIPS", 20: "PowerPC", 21: "PowerPC64", 22: "s390x", 40: "ARM (32-bit)", 62: "x86_64",
    183: "aarch64", 243: "riscv64", 258: "loongarch64",
}
ET_DYN = 3
PT_LOAD, PT_DYNAMIC = 1, 2
SHT_DYNSYM = 11
DT_NULL, DT_NEEDED, DT_STRTAB, DT_SONAME = 0, 1, 5, 14
SHN_UNDEF = 0
STB_GLOBAL, STB_WEAK = 1, 2
# Most of an ELF file a check reads; the dynamic symbol table of libdwivedi is a few tens of kB.
READ_LIMIT = 64 << 20


class Problem:
    """Why a library file cannot be used: `kind` (missing, not_a_file, damaged, architecture,
    too_old, too_new, not_dwivedi, unloadable, changed) and a one-line `message`."""

    def __init__(self, kind: str, message: str) -> None:
        self.kind = kind
        self.message = message

    def __repr__(self) -> str:
        return f"Problem({self.kind!r}, {self.message!r})"

    def __str__(self) -> str:
        return self.message


class ElfInfo:
    """What check_file reads from an ELF file."""

    def __init__(self) -> None:
        self.elf_class = 0      # 1: 32-bit, 2: 64-bit
        self.little = True
        self.machine = 0
        self.type = 0
        self.soname: Optional[str] = None
        self.needed: List[str] = []
        self.defined: Optional[set] = None  # defined global dynamic symbols; None if no section headers


def machine_name(machine: int, elf_class: int = 0) -> str:
    name = MACHINES.get(machine, f"an unknown CPU (ELF machine {machine})")
    if machine == 40 and elf_class == 2:
        name = "ARM"
    return name


def host() -> Tuple[int, int, bool]:
    """(ELF class, machine, little-endian) of the running process (Blender itself), from the ELF
    header of /proc/self/exe; from platform.machine() where that cannot be read."""
    try:
        with open("/proc/self/exe", "rb") as f:
            head = f.read(20)
        if head[:4] == b"\x7fELF" and len(head) == 20:
            little = head[5] == 1
            machine = struct.unpack("<H" if little else ">H", head[18:20])[0]
            return head[4], machine, little
    except OSError:
        pass
    by_name = {"x86_64": 62, "amd64": 62, "aarch64": 183, "arm64": 183, "i386": 3, "i686": 3, "riscv64": 243,
               "ppc64le": 21, "s390x": 22}
    machine = by_name.get(platform.machine().lower(), 0)
    return (2 if struct.calcsize("P") == 8 else 1), machine, True


def host_description() -> str:
    elf_class, machine, _little = host()
    return f"{machine_name(machine, elf_class)}" + (" (32-bit)" if elf_class == 1 and machine == 62 else "")


def _read_elf(data: bytes, size: int, path: str) -> Tuple[Optional[ElfInfo], Optional[Problem]]:
    """Parses the header, checks every table lies inside the file, reads SONAME, DT_NEEDED and the
    defined dynamic symbols."""
    if size == 0:
        return None, Problem("damaged", f"{path} is damaged: the file is empty (0 bytes)")
    if data[:4] != b"\x7fELF":
        return None, Problem("damaged", f"{path} is damaged or not a library: it is not an ELF file "
                                        f"(it begins with {data[:4]!r})")
    if len(data) < 52 or data[4] not in (1, 2) or data[5] not in (1, 2):
        return None, Problem("damaged", f"{path} is damaged: its ELF header is truncated or invalid "
                                        f"({size} bytes)")
    info = ElfInfo()
    info.elf_class, info.little = data[4], data[5] == 1
    e = "<" if info.little else ">"
    wide = info.elf_class == 2
    if wide and len(data) < 64:
        return None, Problem("damaged", f"{path} is damaged: its ELF header is truncated ({size} bytes)")
    info.type, info.machine = struct.unpack(e + "HH", data[16:20])
    if wide:
        phoff, shoff = struct.unpack(e + "QQ", data[32:48])
        phentsize, phnum, shentsize, shnum = struct.unpack(e + "HHHH", data[54:62])
    else:
        phoff, shoff = struct.unpack(e + "II", data[28:36])
        phentsize, phnum, shentsize, shnum = struct.unpack(e + "HHHH", data[42:50])
    needed_end = max(phoff + phentsize * phnum, shoff + shentsize * shnum if shoff else 0)
    if needed_end > size:
        return info, Problem("damaged", f"{path} is damaged: truncated ({size} bytes, its headers need "
                                        f"{needed_end})")
    # Program headers: loadable segments inside the file, the dynamic segment.
    loads: List[Tuple[int, int, int]] = []  # (vaddr, offset, filesz)
    dynamic: Optional[Tuple[int, int]] = None
    for i in range(phnum):
        at = phoff + i * phentsize
        if at + phentsize > len(data):
            break
        if wide:
            p_type, _flags, p_offset, p_vaddr, _paddr, p_filesz = struct.unpack(e + "IIQQQQ", data[at:at + 40])
        else:
            p_type, p_offset, p_vaddr, _paddr, p_filesz = struct.unpack(e + "IIIII", data[at:at + 20])
        if p_type == PT_LOAD:
            if p_offset + p_filesz > size:
                return info, Problem("damaged", f"{path} is damaged: truncated ({size} bytes, its code and data "
                                                f"need {p_offset + p_filesz})")
            loads.append((p_vaddr, p_offset, p_filesz))
        elif p_type == PT_DYNAMIC:
            dynamic = (p_offset, p_filesz)

    def offset_of(vaddr: int) -> Optional[int]:
        for start, offset, filesz in loads:
            if start <= vaddr < start + filesz:
                return offset + (vaddr - start)
        return None

    def string_at(base: int, index: int) -> Optional[str]:
        at = base + index
        if at >= len(data):
            return None
        end = data.find(b"\0", at)
        return data[at:end if end >= 0 else len(data)].decode("utf-8", "replace")

    if dynamic is not None and info.machine in MACHINES and info.type == ET_DYN:
        entry = 16 if wide else 8
        fmt = e + ("qQ" if wide else "iI")
        tags: List[Tuple[int, int]] = []
        offset, filesz = dynamic
        for at in range(offset, min(offset + filesz, len(data)) - entry + 1, entry):
            tag, value = struct.unpack(fmt, data[at:at + entry])
            if tag == DT_NULL:
                break
            tags.append((tag, value))
        strtab = next((offset_of(v) for t, v in tags if t == DT_STRTAB), None)
        if strtab is not None:
            for tag, value in tags:
                if tag == DT_SONAME:
                    info.soname = string_at(strtab, value)
                elif tag == DT_NEEDED:
                    name = string_at(strtab, value)
                    if name:
                        info.needed.append(name)
    # Section headers (kept by strip): the defined global symbols of .dynsym.
    if shoff and shnum:
        sections = []
        for i in range(shnum):
            at = shoff + i * shentsize
            if wide:
                _name, sh_type, _f, _a, sh_offset, sh_size, sh_link, _info, _al, sh_entsize = struct.unpack(
                    e + "IIQQQQIIQQ", data[at:at + 64])
            else:
                _name, sh_type, _f, _a, sh_offset, sh_size, sh_link, _info, _al, sh_entsize = struct.unpack(
                    e + "IIIIIIIIII", data[at:at + 40])
            sections.append((sh_type, sh_offset, sh_size, sh_link, sh_entsize))
        for sh_type, sh_offset, sh_size, sh_link, sh_entsize in sections:
            if sh_type != SHT_DYNSYM or sh_link >= len(sections):
                continue
            if sh_offset + sh_size > size:
                return info, Problem("damaged", f"{path} is damaged: truncated ({size} bytes, its symbol table "
                                                f"needs {sh_offset + sh_size})")
            strtab_offset = sections[sh_link][1]
            info.defined = set()
            entsize = sh_entsize or (24 if wide else 16)
            for at in range(sh_offset, sh_offset + sh_size - entsize + 1, entsize):
                if wide:
                    st_name, st_info, _other, st_shndx = struct.unpack(e + "IBBH", data[at:at + 8])
                else:
                    st_name, = struct.unpack(e + "I", data[at:at + 4])
                    st_info, _other, st_shndx = struct.unpack(e + "BBH", data[at + 12:at + 16])
                if st_shndx != SHN_UNDEF and (st_info >> 4) in (STB_GLOBAL, STB_WEAK):
                    name = string_at(strtab_offset, st_name)
                    if name:
                        info.defined.add(name)
    return info, None


def check_file(path: str, abi_version: int, functions: Iterable[str] = (),
               base_name: str = "libdwivedi.so") -> Optional[Problem]:
    """None if `path` looks loadable as libdwivedi of ABI `abi_version` defining `functions` in
    this process, else the Problem. Reads the file only (loads nothing)."""
    if not os.path.lexists(path):
        return Problem("missing", f"{path} is missing")
    try:
        with open(path, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            if not os.path.isfile(path):
                return Problem("not_a_file", f"{path} is not a regular file")
            data = f.read(min(size, READ_LIMIT))
    except IsADirectoryError:
        return Problem("not_a_file", f"{path} is a folder, not a library file")
    except OSError as error:
        if not os.path.exists(path):  # a dangling symbolic link
            return Problem("missing", f"{path} is missing (a link to a file that is not there)")
        return Problem("unreadable", f"{path} cannot be read: {error.strerror or error}")
    info, problem = _read_elf(data, size, path)
    if info is not None and info.type != ET_DYN and problem is None:
        problem = Problem("not_dwivedi", f"{path} is not a shared library (ELF type {info.type})")
    host_class, host_machine, host_little = host()
    if info is not None and (info.machine != host_machine or info.elf_class != host_class
                             or info.little != host_little):
        # Said first even when the file is damaged too: it is the actionable part.
        built = machine_name(info.machine, info.elf_class) + (" (32-bit)" if info.elf_class == 1 else "")
        runs = machine_name(host_machine, host_class) + (" (32-bit)" if host_class == 1 else "")
        if info.machine == host_machine and info.elf_class == host_class:
            built += " big-endian" if not info.little else " little-endian"
        return Problem("architecture", f"{path} is built for {built}, this Blender runs on {runs}: install the "
                                       "add-on package made for this machine")
    if problem is not None:
        return problem
    assert info is not None
    soname = info.soname or ""
    if not soname.startswith(base_name + "."):
        return Problem("not_dwivedi", f"{path} is not libdwivedi (its SONAME is {soname or 'missing'}, "
                                      f"expected {base_name}.{abi_version})")
    generation = soname[len(base_name) + 1:]
    if not generation.isdigit():
        return Problem("not_dwivedi", f"{path} is not libdwivedi (SONAME {soname})")
    if int(generation) < abi_version:
        return Problem("too_old", f"{path} is too old: libdwivedi ABI {generation} ({soname}), this add-on needs "
                                  f"ABI {abi_version} ({base_name}.{abi_version})")
    if int(generation) > abi_version:
        return Problem("too_new", f"{path} is too new: libdwivedi ABI {generation} ({soname}), this add-on is "
                                  f"written for ABI {abi_version}: update the add-on")
    if info.defined is not None:
        missing = [name for name in functions if name not in info.defined]
        if missing:
            shown = ", ".join(missing[:4]) + (f" and {len(missing) - 4} more" if len(missing) > 4 else "")
            return Problem("too_old", f"{path} is too old for this add-on: it lacks {shown}")
    return None


def file_identity(path: str) -> Optional[Tuple[int, int, int, int]]:
    """(device, inode, size, mtime in ns) of `path`, None if it cannot be read."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def read_elf(path: str) -> Tuple[Optional[ElfInfo], Optional[Problem]]:
    """The ElfInfo of `path` (SONAME, DT_NEEDED, exported symbols) and any Problem found reading it."""
    try:
        with open(path, "rb") as f:
            data = f.read(READ_LIMIT)
            size = os.fstat(f.fileno()).st_size
    except OSError as error:
        return None, Problem("unreadable", f"{path} cannot be read: {error.strerror or error}")
    return _read_elf(data, size, path)
