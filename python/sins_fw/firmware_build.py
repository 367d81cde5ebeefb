"""Build a user's F28335 firmware, unmodified, for the host against the emulated board, and run it.

C is compiled as C (``-std=gnu11``), C++ as C++ (``-std=gnu++17``), by Debian's clang 14 with the
build's LLVM pass (``firmware_c/pass``): every volatile access, and every access to one of TI's
register-file objects (``SpiaRegs``, ``PieVectTable``, ...), becomes a call into the runtime, which
reaches the emulated board when the address is a modelled register of the C28x data space and plain
memory otherwise. The register-file objects are placed by the link in the runtime's image of that
space at their C28x addresses (:data:`REGISTER_FILES`, those of TI's ``DSP2833x_Headers_nonBIOS.cmd``),
and the pass maps a raw address (``*(volatile Uint16 *)0x701B``) to the same image, so that TI's own
headers and the replacements of ``firmware_c/include`` behave alike. ``sins_fw_prelude.h`` is
force-included (TI's ``interrupt``, ``cregister``, ``far``, ``asm``/``__asm``, the DSP28 data types,
``void main``); TI's pragmas are ignored by clang, silently (the build reads ``CODE_SECTION(f,
"ramfuncs")``: see :func:`ramfuncs`). Each register access is charged the cycles of
``firmware_model/c28x-costs.toml`` ``[io]``, and every basic block of the firmware's code the C28x
cycles of its optimised IR, priced at compile time by the pass (:func:`block_costs`,
docs/c-cycles.md). The result is a shared library linked against the C ABI
library (``rust/cabi``), which :mod:`sins_fw.firmware_run` runs on a trace.

The input is files, folders, or a CCS project (its ``.project``/``.cproject`` or its folder):
:func:`read_project`. The firmware's ``float``/``double`` are the host's or the C28x's
(``float_mode``: the same pass then makes every float operation the ``c28x-f32`` backend's),
IQmathLib.h is the ``iq`` backend's (sins_fw.firmware_arith, docs/c-arithmetic.md).
"""

from __future__ import annotations

import hashlib
import os
import re
import shlex
import shutil
import subprocess
import tempfile
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path

from sins_fw import firmware_arith
from sins_fw.atomic import atomic_path
from sins_fw.errors import ConfigError, InputError, ProfileError
from sins_fw.firmware_paths import (
    CXX_SUFFIXES,
    FIRMWARE_C,
    Project,
    cabi_dirs,
    read_project,
)
from sins_fw.profile import MODEL_DIR, Profile, ProfileValues, cost_table_text, load_profile

#: The host replacements of TI's support sources (DSP2833x_common/source), linked into every firmware.
TI_SUPPORT = FIRMWARE_C / "ti"
#: TI's support sources that cannot build against the replacement headers (``firmware_c/include``):
#: a firmware source of one of these names is left out, and the replacement of the same name stands
#: in, unless TI's own headers are on the include path (:func:`with_ti_support`; firmware_c/ti/README.md).
#: TI's DSP2833x_GlobalVariableDefs.c defines every register file of the chip, some of whose
#: structures (XINTRUPT_REGS, DEV_EMU_REGS, ...) the replacement headers do not declare; with TI's
#: headers it compiles as given and the pass makes its definitions declarations (the build places
#: the objects itself).
REPLACED_TI_SOURCES = ("DSP2833x_GlobalVariableDefs.c",)
#: The header whose presence on the include path tells that TI's own headers are used.
TI_DEVICE_HEADER = "DSP2833x_Device.h"
#: TI's register-file objects and their C28x data addresses (TI's DSP2833x_Headers_nonBIOS.cmd). The
#: build defines each at ``sins_fw_io + 2·address`` (the runtime's image of the data space:
#: :func:`placement_assembly`).
REGISTER_FILES: Mapping[str, int] = {
    "DevEmuRegs": 0x0880,
    "FlashRegs": 0x0A80,
    "CsmRegs": 0x0AE0,
    "AdcMirror": 0x0B00,
    "XintfRegs": 0x0B20,
    "CpuTimer0Regs": 0x0C00,
    "CpuTimer1Regs": 0x0C08,
    "CpuTimer2Regs": 0x0C10,
    "PieCtrlRegs": 0x0CE0,
    "DmaRegs": 0x1000,
    "McbspaRegs": 0x5000,
    "McbspbRegs": 0x5040,
    "ECanaRegs": 0x6000,
    "ECanaLAMRegs": 0x6040,
    "ECanaMOTSRegs": 0x6080,
    "ECanaMOTORegs": 0x60C0,
    "ECanaMboxes": 0x6100,
    "ECanbRegs": 0x6200,
    "ECanbLAMRegs": 0x6240,
    "ECanbMOTSRegs": 0x6280,
    "ECanbMOTORegs": 0x62C0,
    "ECanbMboxes": 0x6300,
    **{f"EPwm{i}Regs": 0x6800 + 0x40 * (i - 1) for i in range(1, 7)},
    **{f"ECap{i}Regs": 0x6A00 + 0x20 * (i - 1) for i in range(1, 7)},
    "EQep1Regs": 0x6B00,
    "EQep2Regs": 0x6B40,
    "GpioCtrlRegs": 0x6F80,
    "GpioDataRegs": 0x6FC0,
    "GpioIntRegs": 0x6FE0,
    "SysCtrlRegs": 0x7010,
    "SpiaRegs": 0x7040,
    "SciaRegs": 0x7050,
    "XIntruptRegs": 0x7070,
    "AdcRegs": 0x7100,
    "ScibRegs": 0x7750,
    "ScicRegs": 0x7770,
    "I2caRegs": 0x7900,
    "CsmPwl": 0x33FFF8,
    "PartIdRegs": 0x380090,
}
#: The other objects the build places: the vector table and the CPU's IER and IFR.
RUNTIME_OBJECTS: Mapping[str, str] = {
    "PieVectTable": "sins_fw_vectors",
    "IER": "sins_fw_cregs",
    "IFR": "sins_fw_cregs + 8",
}
#: The runtime's arrays: the C28x data space (0x400000 16-bit words), the 128 vectors (host
#: pointers), IER and IFR.
RUNTIME_ARRAYS: Mapping[str, int] = {
    "sins_fw_io": 2 * 0x400000,
    "sins_fw_vectors": 8 * 128,
    "sins_fw_cregs": 16,
}


#: 16-bit words of the ramfuncs section's image per function placed there (and at least this many).
RAMFUNC_WORDS = 8

#: TI's pragma that places a function in a section: ``#pragma CODE_SECTION(func, "section")`` (C).
_CODE_SECTION = re.compile(
    r'^[ \t]*#[ \t]*pragma[ \t]+CODE_SECTION[ \t]*\([ \t]*(\w+)[ \t]*,[ \t]*"(\w+)"', re.M
)


def ramfuncs(sources: Sequence[Path]) -> list[str]:
    """The functions the sources place in section ``ramfuncs`` with TI's ``#pragma CODE_SECTION(f,
    "ramfuncs")`` (C's form; clang ignores the pragma itself): the pass makes their entry check that
    the section was copied to RAM (``MemCopy(&RamfuncsLoadStart, ...)``) before they run."""
    names: set[str] = set()
    for src in sources:
        try:
            text = src.read_bytes().decode("utf-8", errors="replace")
        except OSError:
            continue
        names.update(f for f, section in _CODE_SECTION.findall(text) if section == "ramfuncs")
    return sorted(names)


def placement_assembly(n_ramfuncs: int = 0) -> str:
    """The assembly that defines the runtime's arrays (:data:`RUNTIME_ARRAYS`) and places each
    register-file object in them: a symbol at an offset of an array of the same object file, which
    the dynamic linker relocates with it (``--defsym`` would make an absolute address). It also gives
    TI's linker symbols of section ramfuncs: ``RamfuncsLoadStart``…``RamfuncsLoadEnd``, its load
    image (:data:`RAMFUNC_WORDS` words of a fixed pattern per function of ``n_ramfuncs``),
    ``RamfuncsRunStart``, its place in RAM (zeros until the firmware copies it), and
    ``RamfuncsLoadSize``, whose address is the image's size in bytes (the host's memcpy counts bytes)."""
    words = RAMFUNC_WORDS * max(1, n_ramfuncs)
    lines = ["\t.section .rodata", "\t.globl RamfuncsLoadStart", "\t.globl RamfuncsLoadEnd", "\t.p2align 4"]
    lines += ["RamfuncsLoadStart:"]
    lines += [f"\t.short {0x7600 + k % 256}" for k in range(words)]
    lines += ["RamfuncsLoadEnd:", "\t.short 0"]
    lines += ["\t.globl RamfuncsLoadSize", "\t.hidden RamfuncsLoadSize"]
    lines += [f"\t.set RamfuncsLoadSize, {2 * words}"]
    lines += ["\t.bss", "\t.globl RamfuncsRunStart", "\t.p2align 4", "RamfuncsRunStart:"]
    lines += [f"\t.zero {2 * words}"]
    for name, size in RUNTIME_ARRAYS.items():
        lines += [f"\t.globl {name}", "\t.p2align 6", f"\t.type {name}, @object", f"\t.size {name}, {size}"]
        lines += [f"{name}:", f"\t.zero {size}"]
    placed = {**{n: f"sins_fw_io + {2 * a}" for n, a in REGISTER_FILES.items()}, **RUNTIME_OBJECTS}
    for name, where in placed.items():
        lines += [f"\t.globl {name}", f"\t.type {name}, @object", f"\t.set {name}, {where}"]
    lines.append('\t.section .note.GNU-stack,"",@progbits')
    return "\n".join(lines) + "\n"


#: How many of the compiler's error lines a build error quotes.
QUOTED_ERRORS = 5
#: Debian's clang and LLVM (the pass is built against LLVM's headers); `make firmware-toolchain`
#: installs them.
CLANG = os.environ.get("SINS_FW_CLANG", "clang-14")
CLANGXX = os.environ.get("SINS_FW_CLANGXX", "clang++-14")
LLVM_CONFIG = os.environ.get("SINS_FW_LLVM_CONFIG", "llvm-config-14")
TOOLCHAIN_HINT = (
    "install Debian's clang-14 and llvm-14-dev (`make firmware-toolchain`, "
    "or apt-get install clang-14 llvm-14-dev)"
)


def cabi_library_dir() -> Path:
    """The folder of ``libsins_cabi.so`` (:func:`cabi_dirs`)."""
    return cabi_dirs()[0]


def with_ti_support(
    sources: Sequence[Path], include: Sequence[str | os.PathLike[str]] = ()
) -> tuple[list[Path], list[str]]:
    """The firmware's sources plus the host replacements of TI's support sources (``firmware_c/ti``),
    and the names of the firmware's own copies of TI's sources that are left out for them
    (:data:`REPLACED_TI_SOURCES`: only when TI's own headers, a ``DSP2833x_Device.h``, are in none of
    the ``include`` folders and the sources' folders). The replacements' definitions are weak: a
    firmware's own ``InitSysCtrl``, ``InitPieVectTable`` or ``TINT0_ISR`` (its own copy of TI's support
    sources, compiled as given) takes the place of the replacement's."""
    folders = [Path(d) for d in include] + [s.parent for s in sources]
    if any((d / TI_DEVICE_HEADER).is_file() for d in folders):
        return [*sources, *sorted(TI_SUPPORT.glob("*.c"))], []
    kept = [s for s in sources if s.name not in REPLACED_TI_SOURCES]
    replaced = sorted({s.name for s in sources if s.name in REPLACED_TI_SOURCES})
    return kept + sorted(TI_SUPPORT.glob("*.c")), replaced


def _clock_defines(profile: ProfileValues | None) -> list[str]:
    """``-D`` of the profile's clocks (``[clocks]``: SYSCLKOUT = crystal_hz · pllcr / divsel) for the
    replacement DSP2833x_Examples.h: TI's DSP28_PLLCR, DSP28_DIVSEL, CPU_FRQ_150MHZ, CPU_RATE. Default:
    the reference profile."""
    if profile is None:
        profile = load_profile("reference")
    crystal, pllcr, divsel = (int(profile.get(f"clocks.{k}")) for k in ("crystal_hz", "pllcr", "divsel"))
    sysclk = crystal * (pllcr or 1) // divsel
    # TI's PLLSTS.DIVSEL field for that divider: 2 → /2, 3 → /1, 0 (or 1) → /4.
    field_value = {1: 3, 2: 2, 4: 0}.get(divsel, 2)
    return [f"-DSINS_FW_PLLCR={pllcr}", f"-DSINS_FW_DIVSEL={field_value}", f"-DSINS_FW_SYSCLK_HZ={sysclk}"]


def _tool(name: str) -> str:
    found = shutil.which(name)
    if found is None:
        raise ConfigError(f"`{name}` not found: the firmware build needs it; {TOOLCHAIN_HINT}")
    return found


def block_costs(profile: ProfileValues | None) -> dict[str, int]:
    """The prices the pass gives a basic block's instructions, in C28x cycles, from the profile's cost
    table (``timing.costs``, the table the model's operation counter uses; default the reference
    profile's ``firmware_model/c28x-costs.toml``): ``[instructions]`` (integer and address arithmetic,
    loads and stores with the data memory's wait states, branches, calls) under their own names, and
    ``[float]`` / ``[iq]`` as ``float.add``, ``iq.mul``, ... A missing section or a price that is not
    cycles is a :class:`~sins_fw.errors.ProfileError` naming the file and key."""
    if profile is None:
        profile = load_profile("reference")
    if not isinstance(profile, Profile) or not profile.get("timing.costs"):
        text, source = (MODEL_DIR / "c28x-costs.toml").read_text(encoding="utf-8"), "c28x-costs.toml"
    else:
        text, source = cost_table_text(profile)
    table = tomllib.loads(text)
    out: dict[str, int] = {}
    for section in ("instructions", "float", "iq"):
        if not isinstance(table.get(section), dict):
            raise ProfileError(f"{source}: no section [{section}]: the firmware build prices it")
        for key, v in table[section].items():
            if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                raise ProfileError(
                    f"{source}: key `{section}.{key}` = {v!r}: expected cycles (an integer ≥ 0)"
                )
            out[key if section == "instructions" else f"{section}.{key}"] = v
    return out


def pass_plugin() -> Path:
    """The build's LLVM pass (``firmware_c/pass/sins_fw_pass.cpp``) as a clang plugin, compiled once
    per source and LLVM version into ``$SINS_FW_CACHE`` (default ``~/.cache/sins-fw``)."""
    source = FIRMWARE_C / "pass" / "sins_fw_pass.cpp"
    clangxx, llvm_config = _tool(CLANGXX), _tool(LLVM_CONFIG)
    version = subprocess.run(
        [llvm_config, "--version"], capture_output=True, text=True, check=False
    ).stdout.strip()
    digest = hashlib.sha256(source.read_bytes() + version.encode()).hexdigest()[:16]
    cache = Path(os.environ.get("SINS_FW_CACHE") or Path.home() / ".cache" / "sins-fw")
    plugin = cache / f"sins_fw_pass-{digest}.so"
    if plugin.is_file():
        return plugin
    cxxflags = subprocess.run(
        [llvm_config, "--cxxflags"], capture_output=True, text=True, check=False
    ).stdout.split()
    cache.mkdir(parents=True, exist_ok=True)
    with atomic_path(plugin) as tmp:
        run = subprocess.run(
            [clangxx, "-shared", "-fPIC", "-O2", *cxxflags, str(source), "-o", str(tmp)],
            capture_output=True,
            check=False,
        )
        if run.returncode != 0:
            raise ConfigError(
                f"the build's LLVM pass does not compile ({TOOLCHAIN_HINT}):\n  " + _text(run.stderr)[-2000:]
            )
    return plugin


#: The optimisation levels of a build, as cl2000's ``--opt_level``, and the host compiler's level that
#: stands for each (docs/c-cycles.md): ``2`` (the default) clang's -O1, whose optimised IR the pass
#: prices as cl2000 -O2's code; ``off`` clang's -O0 (every variable in memory, no inlining), as
#: cl2000 builds without optimisation (a CCS project's Debug configuration).
OPT_LEVELS = {"2": "-O1", "off": "-O0"}


def check_opt_level(opt_level: str) -> None:
    if opt_level not in OPT_LEVELS:
        raise InputError(f"optimisation level `{opt_level}`: expected one of {', '.join(OPT_LEVELS)}")


def compile_flags(
    project: Project,
    sources: Sequence[Path],
    float_mode: str,
    include: Sequence[str | os.PathLike[str]] = (),
    defines: Sequence[str] = (),
    profile: ProfileValues | None = None,
    opt_level: str = "2",
) -> list[str]:
    """The flags every source of ``project`` is compiled with, but the language standard: the
    optimisation and code generation, the prelude and the float mode's headers, TI's clock macros
    from the profile, the ``-D`` definitions (``defines``, then the project's) and the include path
    (the ``-I`` folders, the project's, the sources' folders, the replacement headers, the C ABI's).
    A malformed ``-D`` or a missing ``-I`` folder is an :class:`~sins_fw.errors.InputError`."""
    firmware_arith.check_float_mode(float_mode)
    check_opt_level(opt_level)
    for d in defines:
        if not re.fullmatch(r"[A-Za-z_]\w*(=.*)?", d):
            raise InputError(f"-D {d}: expected NAME or NAME=VALUE")
    for i in include:
        if not Path(i).is_dir():
            raise InputError(f"-I {i}: no such folder")
    _, cabi_include = cabi_dirs()
    ours = FIRMWARE_C / "include"
    folders: list[Path] = []
    for d in [*map(Path, include), *project.include, *(s.parent for s in sources if s.parent != TI_SUPPORT)]:
        if d.resolve() not in folders:
            folders.append(d.resolve())
    return [
        OPT_LEVELS[opt_level],
        "-g",
        "-fPIC",
        "-fexceptions",
        "-fno-strict-aliasing",
        "-fwrapv",
        "-Wno-unknown-pragmas",
        "-Wno-main-return-type",
        "-include",
        str(ours / "sins_fw_prelude.h"),
        *firmware_arith.flags(float_mode, ours),
        *_clock_defines(profile),
        *(f"-D{d}" for d in [*defines, *project.defines]),
        *(f"-I{d}" for d in folders),
        f"-I{ours}",
        f"-I{cabi_include}",
    ]


def _language(source: Path) -> tuple[str, str]:
    """The compiler and the language standard of ``source``: C++ for the C++ suffixes, else C."""
    if source.suffix in CXX_SUFFIXES:
        return _tool(CLANGXX), "-std=gnu++17"
    return _tool(CLANG), "-std=gnu11"


def included_headers(
    paths: Sequence[str | os.PathLike[str]],
    float_mode: str = "host",
    include: Sequence[str | os.PathLike[str]] = (),
    defines: Sequence[str] = (),
    profile: ProfileValues | None = None,
) -> list[Path]:
    """The headers the sources of ``paths`` include, as the build's compiler finds them with the
    build's flags (:func:`compile_flags`; ``-MM -MG``: the system's headers left out, a missing one
    listed by name). Empty when the project, the flags or the compiler are not usable: the build then
    says why."""
    try:
        project = read_project(paths)
        sources, _ = with_ti_support(project.sources, [*include, *project.include])
        common = compile_flags(project, sources, float_mode, include, defines, profile)
    except (InputError, ConfigError):
        return []
    headers: list[Path] = []
    for source in project.sources:
        try:
            compiler, std = _language(source)
        except ConfigError:
            return []
        run = subprocess.run(
            [compiler, std, *common, "-MM", "-MG", str(source)],
            capture_output=True,
            check=False,
            env=firmware_arith.c_locale(),
        )
        if run.returncode != 0:
            continue
        # `target.o: dep dep \` lines; a name with spaces is escaped as make does.
        text = run.stdout.decode("utf-8", errors="surrogateescape")
        words = shlex.split(text.replace("\\\n", " ").replace("$$", "$"))
        headers += [Path(w) for w in words[1:] if not w.endswith(":") and Path(w) != source]
    return sorted(set(headers))


def build_firmware(
    paths: Sequence[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    float_mode: str = "host",
    include: Sequence[str | os.PathLike[str]] = (),
    defines: Sequence[str] = (),
    profile: ProfileValues | None = None,
    opt_level: str = "2",
) -> Path:
    """Compile the firmware (files, folders or a CCS project: :func:`read_project`) into the shared
    library ``out``, its ``float`` and ``double`` in ``float_mode`` (``host`` or ``c28x``:
    sins_fw.firmware_arith). ``include`` and ``defines`` (``NAME`` or ``NAME=VALUE``) come before the
    project's own; the profile's clocks define TI's clock macros (:func:`_clock_defines`; default the
    reference profile). A source that does not compile, or a link that fails, raises
    :class:`~sins_fw.errors.InputError` quoting the compiler's or linker's first errors (file:line,
    the undefined symbol); ``out`` is then left as it was.

    The include path: the ``-I`` folders, the project's, the sources' folders, then the replacement
    headers (``firmware_c/include``), so that a project's own copies of TI's headers are used as they
    are. The pass prices every basic block of the firmware's sources in C28x cycles at the end of the
    optimisation pipeline (:func:`block_costs`) and calls the runtime there with them, which charges
    the block's time and lets interrupts in; an idle ``for (;;) {}`` calls ``sins_fw_idle`` instead.
    ``-g`` keeps the sources' lines, for the error that names a loop that can never end.
    ``opt_level`` is the build's optimisation as cl2000's (:data:`OPT_LEVELS`): ``2`` (default) or
    ``off``, the code the pass prices."""
    project = read_project(paths)
    sources, _ = with_ti_support(project.sources, [*include, *project.include])
    common = compile_flags(project, sources, float_mode, include, defines, profile, opt_level)
    clang, clangxx = _tool(CLANG), _tool(CLANGXX)
    plugin = pass_plugin()
    libdir, cabi_include = cabi_dirs()
    ours = FIRMWARE_C / "include"
    env = {
        **firmware_arith.c_locale(),
        "SINS_FW_PASS_SYMBOLS": ",".join([*REGISTER_FILES, *RUNTIME_OBJECTS]),
        "SINS_FW_PASS_C28X_FLOAT": "1" if float_mode == "c28x" else "0",
        "SINS_FW_PASS_COSTS": ",".join(f"{k}={v}" for k, v in sorted(block_costs(profile).items())),
        "SINS_FW_PASS_RAMFUNCS": ",".join(in_ram := ramfuncs(sources)),
    }
    with atomic_path(out) as tmp, tempfile.TemporaryDirectory(prefix="sins-fw-build-") as work:
        objects = []
        for i, src in enumerate(sources):
            cxx = src.suffix in CXX_SUFFIXES
            compiler, std = _language(src)
            flags = [std, *common]
            built, language = firmware_arith.prepare_one(
                src, cxx, float_mode, Path(work), i, [compiler, *flags], [ours]
            )
            tmp_asm = Path(work) / f"{i}_{src.stem}.s"
            _compile(
                [
                    compiler,
                    *flags,
                    f"-fpass-plugin={plugin}",
                    "-x",
                    language,
                    "-S",
                    str(built),
                    "-o",
                    str(tmp_asm),
                ],
                env,
            )
            objects.append(tmp_asm.with_suffix(".o"))
            _compile([clang, "-c", str(tmp_asm), "-o", str(objects[-1])], env)
        runtime = Path(work) / "sins_fw_runtime.o"
        _compile(
            [
                clangxx,
                "-std=c++17",
                "-O2",
                "-g",
                "-fPIC",
                f"-I{cabi_include}",
                *(["-DSINS_FW_C28X_FLOAT"] if float_mode == "c28x" else []),
                "-c",
                str(FIRMWARE_C / "runtime" / "sins_fw_runtime.cpp"),
                "-o",
                str(runtime),
            ],
            env,
        )
        tmp_placement = Path(work) / "sins_fw_placement.s"
        tmp_placement.write_text(placement_assembly(len(in_ram)), encoding="utf-8")
        placed = Path(work) / "sins_fw_placement.o"
        _compile([clang, "-c", str(tmp_placement), "-o", str(placed)], env)
        _compile(
            [
                clangxx,
                "-shared",
                *map(str, objects),
                str(runtime),
                str(placed),
                f"-L{libdir}",
                "-lsins_cabi",
                f"-Wl,-rpath,{libdir.resolve()}",
                "-Wl,--no-undefined",
                "-ldl",
                "-lm",
                "-o",
                str(tmp),
            ],
            env,
            link=True,
        )
    return Path(out)


def _text(data: bytes) -> str:
    """A compiler's output as text: a source in another encoding (GBK comments) quoted as it is."""
    return data.decode("utf-8", errors="replace")


_SCRATCH_OBJECT = re.compile(r"\S*sins-fw-build-[^/\s]*/[^:\s]*\.o:(\([^)]*\))?:?\s*")


def _compile(cmd: list[str], env: Mapping[str, str], *, link: bool = False) -> None:
    """Run the compiler or linker; its errors (file:line, the undefined symbol and where) become an
    InputError."""
    run = subprocess.run(cmd, capture_output=True, check=False, env=dict(env))
    if run.returncode == 0:
        return
    lines = _text(run.stderr).splitlines()
    if link:
        wanted = [
            line
            for line in lines
            if re.search(
                r"undefined reference|multiple definition|first defined here|in function|error", line
            )
            and "collect2" not in line
            and "linker command failed" not in line
        ]
        # The build's scratch objects say nothing to the user: the sources' file:line do.
        wanted = [_SCRATCH_OBJECT.sub("", re.sub(r"^\S*\bld(\.\w+)?: ", "", line)) for line in wanted]
        quoted = "\n  ".join(wanted[: 2 * QUOTED_ERRORS] or lines[-QUOTED_ERRORS:])
        raise InputError(f"the firmware does not link:\n  {quoted}")
    errors = [line for line in lines if re.search(r"\berror\b", line)]
    quoted = "\n  ".join(errors[:QUOTED_ERRORS] or lines[-QUOTED_ERRORS:])
    raise InputError(f"the firmware does not build:\n  {quoted}")
