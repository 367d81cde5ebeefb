"""The arithmetic of a host-built firmware (issue 20, item 4): the C28x float mode (`float`/`double` of
the user's unmodified C as the `c28x-f32` backend computes them), IQmathLib.h on the `iq` backend, and
the 16-bit `int` check. Results of the built .so are compared bit for bit with the Rust backends'
operations (the C ABI library's `sins_c28x_*`/`sins_iq_*`, which call them) and with pinned values."""

from __future__ import annotations

import ctypes
import random
import struct
from pathlib import Path

import pytest

from sins_fw.cli import main
from sins_fw.errors import InputError
from sins_fw.firmware_arith import diagnose_int, rewrite_literals
from sins_fw.firmware_build import build_firmware, cabi_library_dir
from sins_fw.firmware_run import run_c_firmware
from sins_fw.profile import load_profile

ROOT = Path(__file__).resolve().parents[1]

FLOAT_SOURCE = """#include "DSP2833x_Device.h"
#include <math.h>
float a, b;
double r_add, r_sub, r_mul, r_div, r_sqrt, r_neg, r_lit, r_int, r_sin, r_cos, r_atan, r_atan2, r_asin, r_fabs;
Uint16 code;
long i_trunc;
Uint16 lt, size;
void compute(void) {
    r_add = a + b;
    r_sub = a - b;
    r_mul = a * b;
    r_div = a / b;
    r_sqrt = sqrt(a);
    r_neg = -a;
    r_lit = code * 0.05;  /* the published decode's form: an integer times a literal */
    r_int = 2 * a;
    r_sin = sin(a);
    r_cos = cos(a);
    r_atan = atan(a);
    r_atan2 = atan2(a, b);
    r_asin = asin(b);
    r_fabs = fabs(b);
    i_trunc = (long)a;
    lt = a < b;
    size = sizeof(double);
}
void main(void) {}
"""


pytestmark = pytest.mark.usefixtures("cabi_library")


@pytest.fixture(scope="module")
def cabi() -> ctypes.CDLL:
    """The Rust backends' operations, called directly."""
    lib = ctypes.CDLL(str(cabi_library_dir() / "libsins_cabi.so"))
    f = ctypes.c_float
    for name in ("add", "sub", "mul", "div", "atan2"):
        getattr(lib, f"sins_c28x_{name}").argtypes = [f, f]
        getattr(lib, f"sins_c28x_{name}").restype = f
    for name in ("sqrt", "neg", "abs", "sin", "cos", "atan", "asin"):
        getattr(lib, f"sins_c28x_{name}").argtypes = [f]
        getattr(lib, f"sins_c28x_{name}").restype = f
    lib.sins_c28x_from_f64.argtypes = [ctypes.c_double]
    lib.sins_c28x_from_f64.restype = f
    lib.sins_c28x_from_i32.argtypes = [ctypes.c_int32]
    lib.sins_c28x_from_i32.restype = f
    return lib


@pytest.fixture(scope="module")
def float_libs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, ctypes.CDLL]:
    folder = tmp_path_factory.mktemp("float")
    src = folder / "arith.c"
    src.write_text(FLOAT_SOURCE)
    return {
        m: ctypes.CDLL(str(build_firmware([src], folder / f"{m}.so", float_mode=m))) for m in ("host", "c28x")
    }


def bits(x: float) -> int:
    return struct.unpack("<I", struct.pack("<f", x))[0]


def f32(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


ULP1 = 2.0**-23
#: Edge cases: ties to even, subnormal results and inputs, −0, overflow, division by zero, 0/0, sqrt.
EDGE_CASES = [
    (1.0, ULP1 / 2),  # 1 + ½ulp: a tie, to even
    (1.0 + ULP1, ULP1 / 2),  # tie to the even neighbour above
    (3.0, 1.0 + ULP1),  # 3(1+ulp) = 3 + 1.5 ulp(3): rounds up
    (1e-20, 1e-20),  # product below the normal range: flushed to +0
    (1.5 * 2.0**-126, -(2.0**-126)),  # difference subnormal: flushed
    (1e-40, 1.0),  # subnormal input: flushed before use
    (0.0, -1.0),  # 0·(−1) = −0, stored as +0
    (-0.0, 0.0),
    (3.0e38, 3.0e38),  # overflow to ∞
    (5.0, 0.0),  # A/0 = ∞ with A's sign
    (-5.0, 0.0),
    (0.0, 0.0),  # 0/0 = 0 (FS$$DIV)
    (25.0, 3.0),  # fastRTS sqrt(25) is 1 ulp below 5
    (2.0, 3.0),
    (-2.0, 0.5),  # sqrt of a negative: −∞
    (0.7, -0.3),
]


def c28x_results(lib: ctypes.CDLL, a: float, b: float, code: int) -> dict[str, int]:
    ctypes.c_float.in_dll(lib, "a").value = a
    ctypes.c_float.in_dll(lib, "b").value = b
    ctypes.c_uint16.in_dll(lib, "code").value = code
    lib.compute()
    names = (
        "add",
        "sub",
        "mul",
        "div",
        "sqrt",
        "neg",
        "lit",
        "int",
        "sin",
        "cos",
        "atan",
        "atan2",
        "asin",
        "fabs",
    )
    return {n: bits(ctypes.c_float.in_dll(lib, f"r_{n}").value) for n in names}


def backend_results(cabi: ctypes.CDLL, a: float, b: float, code: int) -> dict[str, int]:
    """What the c28x-f32 backend computes for the same C: inputs stored as the FPU holds them."""
    a, b = cabi.sins_c28x_from_f64(a), cabi.sins_c28x_from_f64(b)
    lit = cabi.sins_c28x_mul(cabi.sins_c28x_from_i32(code), cabi.sins_c28x_from_f64(0.05))
    values = {
        "add": cabi.sins_c28x_add(a, b),
        "sub": cabi.sins_c28x_sub(a, b),
        "mul": cabi.sins_c28x_mul(a, b),
        "div": cabi.sins_c28x_div(a, b),
        "sqrt": cabi.sins_c28x_sqrt(a),
        "neg": cabi.sins_c28x_neg(a),
        "lit": lit,
        "int": cabi.sins_c28x_mul(cabi.sins_c28x_from_i32(2), a),
        "sin": cabi.sins_c28x_sin(a),
        "cos": cabi.sins_c28x_cos(a),
        "atan": cabi.sins_c28x_atan(a),
        "atan2": cabi.sins_c28x_atan2(a, b),
        "asin": cabi.sins_c28x_asin(b),
        "fabs": cabi.sins_c28x_abs(b),
    }
    return {k: bits(v) for k, v in values.items()}


def test_c28x_float_mode_is_the_backend_bit_for_bit(float_libs: dict[str, ctypes.CDLL], cabi: ctypes.CDLL):
    lib = float_libs["c28x"]
    rng = random.Random(20)
    cases = EDGE_CASES + [
        (
            f32(rng.uniform(-1, 1) * 2.0 ** rng.randint(-20, 20)),
            f32(rng.uniform(-1, 1) * 2.0 ** rng.randint(-20, 20)),
        )
        for _ in range(300)
    ]
    for a, b in cases:
        code = rng.randint(0, 0x3FFF)
        assert c28x_results(lib, a, b, code) == backend_results(cabi, a, b, code), (a, b, code)


def test_c28x_float_mode_pinned_values(float_libs: dict[str, ctypes.CDLL]):
    """The FPU's rules, pinned (the host build of the same C gives IEEE double's answers instead)."""
    c28x, host = float_libs["c28x"], float_libs["host"]
    r = c28x_results(c28x, 25.0, 0.0, 9)
    assert r["sqrt"] == bits(4.9999995), "fastRTS sqrt(25): estimate + two Newton steps, 1 ulp low"
    assert r["div"] == bits(float("inf")) and c28x_results(c28x, -5.0, 0.0, 0)["div"] == bits(float("-inf"))
    assert c28x_results(c28x, 0.0, 0.0, 0)["div"] == 0
    assert c28x_results(c28x, 1e-20, 1e-20, 0)["mul"] == 0, "subnormal product flushed"
    assert c28x_results(c28x, 0.0, -1.0, 0)["mul"] == 0, "−0 stored as +0"
    assert c28x_results(c28x, 1.0, ULP1 / 2, 0)["add"] == bits(1.0), "tie to even"
    # `code * 0.05`: the literal is a C28x constant and the product the FPU's, not a host double
    # product rounded afterwards (9 × 0.05: the two differ in the last bit).
    assert r["lit"] == bits(f32(f32(9.0) * f32(0.05))) != bits(f32(9 * 0.05))
    assert ctypes.c_uint16.in_dll(c28x, "size").value == 4, "double is 32-bit (COFF ABI)"
    ctypes.c_float.in_dll(host, "a").value = 25.0
    host.compute()
    assert ctypes.c_double.in_dll(host, "r_sqrt").value == 5.0
    assert ctypes.c_uint16.in_dll(host, "size").value == 8


def test_conversions_to_integers_truncate_and_compare(float_libs: dict[str, ctypes.CDLL]):
    lib = float_libs["c28x"]
    c28x_results(lib, -2.75, 1.0, 0)
    assert ctypes.c_long.in_dll(lib, "i_trunc").value == -2
    assert ctypes.c_uint16.in_dll(lib, "lt").value == 1


def run_globals(library: Path, types: dict[str, str]) -> dict[str, float]:
    """Run the firmware's ``main`` on a still board for 50 ms and read the named globals (name → type
    of the globals file) when the run ends."""
    watched = library.with_suffix(".toml")
    watched.write_text(
        "".join(
            f'[[global]]\nname = "{n}"\ntype = "{t}"\ncolumn = "{n.lower()}"\nunit = "1"\n'
            for n, t in types.items()
        )
    )
    return run_c_firmware(library, None, load_profile("reference"), globals_file=watched, until_s=0.05).final


def test_literal_rewrite_leaves_everything_else():
    text = "x = 1e3 + .5f + 0x1E5 + a1e5 + 3.333e-003 + 12 + 0x1.8p3; s = \"2.5\"; // 1.5\n/* 2.0 */ c = '1';"
    assert rewrite_literals(text) == (
        "x = ((float)1e3) + ((float).5f) + 0x1E5 + a1e5 + ((float)3.333e-003)"
        " + 12 + ((float)0x1.8p3); s = \"2.5\"; // 1.5\n/* 2.0 */ c = '1';"
    )


def test_a_literal_in_the_firmwares_own_header_is_rewritten_and_errors_name_the_original(tmp_path: Path):
    (tmp_path / "scale.h").write_text("#define SCALE 0.05\n")
    src = tmp_path / "main.c"
    src.write_text(
        '#include "DSP2833x_Device.h"\n#include "scale.h"\n'
        "Uint16 code = 9;\ndouble x;\nvoid main(void) { x = code * SCALE; }\n"
    )
    final = run_globals(build_firmware([src], tmp_path / "fw.so", float_mode="c28x"), {"x": "float"})
    assert bits(final["x"]) == bits(f32(f32(9.0) * f32(0.05)))
    bad = tmp_path / "bad.c"
    bad.write_text("double y = 1.5;\n\nvoid main(void) { y = undefined_name * 2.0; }\n")
    with pytest.raises(InputError, match=r"bad\.c:3"):
        build_firmware([bad], tmp_path / "bad.so", float_mode="c28x")
    assert not (tmp_path / "bad.so").exists()


def test_an_unknown_float_mode_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    src = tmp_path / "main.c"
    src.write_text("void main(void) {}\n")
    with pytest.raises(InputError, match="float mode `x87`"):
        build_firmware([src], tmp_path / "fw.so", float_mode="x87")
    with pytest.raises(SystemExit) as e:
        main(["build-firmware", str(src), "-o", str(tmp_path / "fw.so"), "--float", "x87"])
    assert e.value.code == 2


IQ_SOURCE = """#define GLOBAL_Q 24
#include "IQmathLib.h"
_iq x = _IQ(1.5), y = _IQ(-2.25), p, q, r, s, c, at, z30, back;
float f;
long n;
void main(void) {
    p = _IQmpy(x, y);
    q = _IQdiv(x, y);
    r = _IQsqrt(x);
    s = _IQsin(x);
    c = _IQcos(x);
    at = _IQatan2(y, x);
    f = _IQtoF(q);
    z30 = _IQ30mpy(_IQ30(0.5), _IQ30(-0.75));
    back = _IQ30toIQ(z30);
    n = _IQint(y);
}
"""


def test_iqmathlib_is_the_iq_backend(tmp_path: Path, cabi: ctypes.CDLL):
    src = tmp_path / "iq.c"
    src.write_text(IQ_SOURCE)
    names = ("x", "y", "p", "q", "r", "s", "c", "at", "z30", "back")
    final = run_globals(
        build_firmware([src], tmp_path / "iq.so"),
        {**dict.fromkeys(names, "int32"), "f": "float", "n": "int64"},
    )
    i32, u8 = ctypes.c_int32, ctypes.c_uint8
    for name, args in {"mpy": [i32, i32, u8], "div": [i32, i32, u8], "atan2": [i32, i32, u8]}.items():
        getattr(cabi, f"sins_iq_{name}").argtypes = args
        getattr(cabi, f"sins_iq_{name}").restype = i32
    for name in ("sqrt", "sin", "cos"):
        getattr(cabi, f"sins_iq_{name}").argtypes = [i32, u8]
        getattr(cabi, f"sins_iq_{name}").restype = i32

    def g(name: str) -> int:
        return int(final[name])

    x, y = g("x"), g("y")
    assert (x, y) == (int(1.5 * 2**24), int(-2.25 * 2**24))
    assert g("p") == cabi.sins_iq_mpy(x, y, 24) == int(-3.375 * 2**24)
    assert g("q") == cabi.sins_iq_div(x, y, 24) == round(-(2 / 3) * 2**24)
    assert g("r") == cabi.sins_iq_sqrt(x, 24) == int(1.5**0.5 * 2**24)
    assert g("s") == cabi.sins_iq_sin(x, 24)
    assert g("c") == cabi.sins_iq_cos(x, 24)
    assert g("at") == cabi.sins_iq_atan2(y, x, 24)
    # _IQtoF truncates the mantissa: −2/3 in Q24 to f32 toward zero.
    q = g("q") / 2**24
    assert abs(final["f"]) <= abs(q) and abs(final["f"] - q) < 2e-7
    # _IQ30mpy floors: 0.5 × −0.75 = −0.375 exactly; back to Q24 by an arithmetic shift.
    assert g("z30") == int(-0.375 * 2**30) and g("back") == int(-0.375 * 2**24)
    assert final["n"] == -3, "_IQint floors (an arithmetic shift)"


INT16_SOURCE = """#include "DSP2833x_Device.h"
long total;
int scaled;
void main(void) {
    int big = 40000;        /* 16-bit int: becomes -25536 on the C28x */
    long sum = 70000L;
    int part = sum;         /* truncated to 16 bits there */
    unsigned int u = 3;
    Uint16 w = u;           /* fine: both 16 bits */
    scaled = part;
    total = sum + big + (long)w;
}
"""


def test_the_16_bit_int_check_flags_what_loses_bits_on_the_c28x(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    src = tmp_path / "int16.c"
    src.write_text(INT16_SOURCE)
    findings = diagnose_int([src])
    lines = sorted(int(f.split(":")[1]) for f in findings)
    assert lines == [5, 7], findings
    assert "40000" in next(f for f in findings if ":5:" in f)
    out = tmp_path / "fw.so"
    assert main(["build-firmware", str(src), "-o", str(out), "--diagnose-int"]) == 0
    text = capsys.readouterr().out
    assert "16-bit int check: 2 conversion(s)" in text and out.exists()
    # The host build itself has nothing to say: int is 32-bit there.
    clean = tmp_path / "clean.c"
    clean.write_text("int x = 1000;\nvoid main(void) { x = x * 2; }\n")
    assert diagnose_int([clean]) == []
