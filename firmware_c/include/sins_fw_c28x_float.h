/* sins-fw C28x float mode (`sins-fw build-firmware --float c28x`), force-included after the prelude:
   `float` and `double` in the firmware's own sources become sins_c28x_float, a 32-bit value whose every
   operation is the C28x FPU's as the `c28x-f32` backend models it (rust/core/src/numerics/c28x.rs):
   TI's COFF ABI makes `double` 32-bit; + − × round to nearest (RND32 = 1, what compiled C runs);
   subnormal results and inputs are flushed to +0, −0 is stored as +0, there is no NaN (∞ instead);
   division and sqrt are fastRTS' estimate + two Newton steps; sin, cos, atan, atan2, asin are the
   backend's model. The build also rewrites the floating literals on the firmware's own lines (after
   preprocessing) into sins_c28x_float(…): the literal rounded to nearest as TI's compiler stores a
   32-bit double, so that `code * 0.05` multiplies in C28x single precision as on target
   (docs/c-arithmetic.md lists what stays different).

   The standard headers are included here, before `float` and `double` are redefined: their own
   declarations keep the host types, and their include guards keep the firmware's later #includes from
   reading them again. */
#ifndef SINS_FW_C28X_FLOAT_H
#define SINS_FW_C28X_FLOAT_H

#ifndef __cplusplus
#error "sins_fw_c28x_float.h: the C28x float mode compiles the firmware as C++ (sins-fw build-firmware)"
#endif

#include <assert.h>
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#include "sins_fw.h"
#include "sins_fw_reg.hpp" /* declares sins_fw_delay_us(double) with the host double */

class sins_c28x_float {
    float v_; /* always canonical: +0, a normal number or ±∞ */

    template <class U>
    static constexpr bool arithmetic = std::is_arithmetic<U>::value && !std::is_same<U, bool>::value;

    static float of(double x) { return sins_c28x_from_f64(x); }
    template <class U>
    static float of_integer(U x) {
        if (std::is_signed<U>::value && sizeof(U) <= 4) return sins_c28x_from_i32(static_cast<int32_t>(x));
        if (!std::is_signed<U>::value && sizeof(U) <= 4) return sins_c28x_from_u32(static_cast<uint32_t>(x));
        return sins_c28x_from_f64(static_cast<float>(x)); /* 64-bit: one rounding to nearest */
    }

public:
    struct bits_tag {};
    /* Uninitialised like a C local; zero as a global. */
    sins_c28x_float() = default;
    constexpr sins_c28x_float(float canonical, bits_tag) : v_(canonical) {}

    /* From a host float/double (a constant, a host value): rounded to nearest f32, canonical. */
    template <class U, typename std::enable_if<std::is_floating_point<U>::value, int>::type = 0>
    sins_c28x_float(U x) : v_(of(static_cast<double>(x))) {}
    /* From an integer: I32TOF32 / UI32TOF32, rounded to nearest. */
    template <class U, typename std::enable_if<std::is_integral<U>::value, int>::type = 0>
    sins_c28x_float(U x) : v_(of_integer(x)) {}

    /* The value as the host's float (exact). */
    float host() const { return v_; }

    /* To a host double (exact), for the host's own functions. */
    operator double() const { return v_; }
    /* To an integer: F32TOI32 / F32TOUI32, truncated toward zero and saturated as the FPU does. */
    template <class I, typename std::enable_if<std::is_integral<I>::value && !std::is_same<I, bool>::value, int>::type = 0>
    operator I() const {
        return std::is_signed<I>::value ? static_cast<I>(sins_c28x_to_i32(v_)) : static_cast<I>(sins_c28x_to_u32(v_));
    }
    explicit operator bool() const { return v_ != 0.0f; }

    friend sins_c28x_float operator+(sins_c28x_float a, sins_c28x_float b) {
        return {sins_c28x_add(a.v_, b.v_), bits_tag{}};
    }
    friend sins_c28x_float operator-(sins_c28x_float a, sins_c28x_float b) {
        return {sins_c28x_sub(a.v_, b.v_), bits_tag{}};
    }
    friend sins_c28x_float operator*(sins_c28x_float a, sins_c28x_float b) {
        return {sins_c28x_mul(a.v_, b.v_), bits_tag{}};
    }
    friend sins_c28x_float operator/(sins_c28x_float a, sins_c28x_float b) {
        return {sins_c28x_div(a.v_, b.v_), bits_tag{}};
    }
    sins_c28x_float operator-() const { return {sins_c28x_neg(v_), bits_tag{}}; }
    sins_c28x_float operator+() const { return *this; }

    /* Canonical values compare as the FPU's CMPF32: host float comparisons. */
    friend bool operator<(sins_c28x_float a, sins_c28x_float b) { return a.v_ < b.v_; }
    friend bool operator>(sins_c28x_float a, sins_c28x_float b) { return a.v_ > b.v_; }
    friend bool operator<=(sins_c28x_float a, sins_c28x_float b) { return a.v_ <= b.v_; }
    friend bool operator>=(sins_c28x_float a, sins_c28x_float b) { return a.v_ >= b.v_; }
    friend bool operator==(sins_c28x_float a, sins_c28x_float b) { return a.v_ == b.v_; }
    friend bool operator!=(sins_c28x_float a, sins_c28x_float b) { return a.v_ != b.v_; }

/* The same with a host arithmetic operand on either side, converted first (as C converts it). Exact
   matches, so they win over the built-in operators the conversions above would otherwise offer. */
#define SINS_C28X_MIXED(RET, OP)                                                                  \
    template <class U, typename std::enable_if<arithmetic<U>, int>::type = 0>                     \
    friend RET operator OP(sins_c28x_float a, U b) { return a OP sins_c28x_float(b); }             \
    template <class U, typename std::enable_if<arithmetic<U>, int>::type = 0>                     \
    friend RET operator OP(U a, sins_c28x_float b) { return sins_c28x_float(a) OP b; }
    SINS_C28X_MIXED(sins_c28x_float, +)
    SINS_C28X_MIXED(sins_c28x_float, -)
    SINS_C28X_MIXED(sins_c28x_float, *)
    SINS_C28X_MIXED(sins_c28x_float, /)
    SINS_C28X_MIXED(bool, <)
    SINS_C28X_MIXED(bool, >)
    SINS_C28X_MIXED(bool, <=)
    SINS_C28X_MIXED(bool, >=)
    SINS_C28X_MIXED(bool, ==)
    SINS_C28X_MIXED(bool, !=)
#undef SINS_C28X_MIXED

    sins_c28x_float &operator+=(sins_c28x_float b) { return *this = *this + b; }
    sins_c28x_float &operator-=(sins_c28x_float b) { return *this = *this - b; }
    sins_c28x_float &operator*=(sins_c28x_float b) { return *this = *this * b; }
    sins_c28x_float &operator/=(sins_c28x_float b) { return *this = *this / b; }
    sins_c28x_float &operator++() { return *this += 1; }
    sins_c28x_float &operator--() { return *this -= 1; }
    sins_c28x_float operator++(int) {
        sins_c28x_float old = *this;
        *this += 1;
        return old;
    }
    sins_c28x_float operator--(int) {
        sins_c28x_float old = *this;
        *this -= 1;
        return old;
    }
};

/* The math library the firmware calls, on C28x values: fastRTS as the backend models it. */
#define SINS_C28X_UNARY(NAME, FN)                                                                          \
    inline sins_c28x_float NAME(sins_c28x_float x) { return {FN(x.host()), sins_c28x_float::bits_tag{}}; } \
    inline sins_c28x_float NAME##f(sins_c28x_float x) { return NAME(x); }
SINS_C28X_UNARY(sqrt, sins_c28x_sqrt)
SINS_C28X_UNARY(sin, sins_c28x_sin)
SINS_C28X_UNARY(cos, sins_c28x_cos)
SINS_C28X_UNARY(atan, sins_c28x_atan)
SINS_C28X_UNARY(asin, sins_c28x_asin)
SINS_C28X_UNARY(fabs, sins_c28x_abs)
/* No model in the backend: f64, rounded once to nearest (the backend's rule for fastRTS functions). */
SINS_C28X_UNARY(acos, sins_c28x_acos)
SINS_C28X_UNARY(tan, sins_c28x_tan)
SINS_C28X_UNARY(exp, sins_c28x_exp)
SINS_C28X_UNARY(log, sins_c28x_log)
#undef SINS_C28X_UNARY

#define SINS_C28X_BINARY(NAME, FN)                                                                        \
    inline sins_c28x_float NAME(sins_c28x_float y, sins_c28x_float x) {                                  \
        return {FN(y.host(), x.host()), sins_c28x_float::bits_tag{}};                                    \
    }                                                                                                    \
    template <class U, typename std::enable_if<std::is_arithmetic<U>::value, int>::type = 0>             \
    inline sins_c28x_float NAME(sins_c28x_float y, U x) { return NAME(y, sins_c28x_float(x)); }          \
    template <class U, typename std::enable_if<std::is_arithmetic<U>::value, int>::type = 0>             \
    inline sins_c28x_float NAME(U y, sins_c28x_float x) { return NAME(sins_c28x_float(y), x); }          \
    inline sins_c28x_float NAME##f(sins_c28x_float y, sins_c28x_float x) { return NAME(y, x); }
SINS_C28X_BINARY(atan2, sins_c28x_atan2)
SINS_C28X_BINARY(pow, sins_c28x_pow)
#undef SINS_C28X_BINARY

/* From here on, the firmware's `float` and `double` are the C28x's 32-bit float. */
#define float sins_c28x_float
#define double sins_c28x_float

#endif
