// The transcendental functions of the whole process, from SLEEF's pure-C
// scalar code (Debian's libsleef: one binary, no run-time CPU dispatch).
// Accuracy: SLEEF's 3.5-ulp variants where it has them (trigonometric,
// logarithms, hyperbolic: as fast as glibc's FMA code, 3-4x faster than its
// 1-ulp ones, measured), the 1-ulp ones otherwise (exp, expm1, log10, log1p,
// pow, the inverse hyperbolic functions). 3.5 ulp is 8e-16 relative: far
// below any physical quantity's uncertainty here.
//
// Why: glibc 2.36's libm picks variants of exp, log, pow, sin, cos, tan,
// atan, atan2, asin, acos, expm1, log2 (and their float forms) by CPU
// features when the program loads (FMA, AVX2); they differ in the last bit
// on some inputs, and a closed loop turns one bit into millimetres. ODE
// (hinge angles: atan2; rotations: sincos), SUNDIALS (CVODE's step-size
// control: pow), FCL and our own units all call them. Functions that are
// not dispatched themselves may call dispatched ones inside libm: erf and
// erfc call its exp (1 call in 38,392 of the PX4Flow model's erf under
// lamp flicker gave other bits on FMA and non-FMA CPUs). So every libm
// function any linesim binary or library imports is defined here, except
// those whose result IEEE 754 defines exactly (sqrt, rounding, fmod, ...);
// tests/platform/deterministic_math_test.cc lists the imports of the
// executables and of every library they load, and fails on any other.
//
// How: these definitions are linked as object code into every linesim
// executable and exported (deterministic_math.list), so the dynamic linker
// binds every library's reference to them before libm's: the executable comes
// first in the global lookup scope, and an unversioned definition satisfies a
// versioned reference (sin@GLIBC_2.2.5). `platform::MathLibrary()` checks the
// binding at run time and provenance records it.
//
// Compiled with -fno-builtin (CMakeLists.txt): GCC must not turn a body into
// a call of the function being defined.
#include <sleef.h>

extern "C" {

#define LINESIM_UNARY(name, sleef) \
  double name(double x) noexcept { return sleef(x); }
#define LINESIM_UNARY_F(name, sleef) \
  float name(float x) noexcept { return sleef(x); }

LINESIM_UNARY(sin, Sleef_sind1_u35purec)
LINESIM_UNARY(cos, Sleef_cosd1_u35purec)
LINESIM_UNARY(tan, Sleef_tand1_u35purec)
LINESIM_UNARY(asin, Sleef_asind1_u35purec)
LINESIM_UNARY(acos, Sleef_acosd1_u35purec)
LINESIM_UNARY(atan, Sleef_atand1_u35purec)
LINESIM_UNARY(exp, Sleef_expd1_u10purec)
LINESIM_UNARY(exp2, Sleef_exp2d1_u35purec)
LINESIM_UNARY(exp10, Sleef_exp10d1_u35purec)
LINESIM_UNARY(expm1, Sleef_expm1d1_u10purec)
LINESIM_UNARY(log, Sleef_logd1_u35purec)
LINESIM_UNARY(log2, Sleef_log2d1_u35purec)
LINESIM_UNARY(log10, Sleef_log10d1_u10purec)
LINESIM_UNARY(log1p, Sleef_log1pd1_u10purec)
LINESIM_UNARY(sinh, Sleef_sinhd1_u35purec)
LINESIM_UNARY(cosh, Sleef_coshd1_u35purec)
LINESIM_UNARY(tanh, Sleef_tanhd1_u35purec)
LINESIM_UNARY(asinh, Sleef_asinhd1_u10purec)
LINESIM_UNARY(acosh, Sleef_acoshd1_u10purec)
LINESIM_UNARY(atanh, Sleef_atanhd1_u10purec)
// The error functions (PX4Flow's exposure under flicker; FCL's erfc): 1
// and 1.5 ulp, SLEEF having no faster ones (about 150 ns against glibc's
// 15, measured; rare calls). hypot (distances in most units): the 3.5-ulp
// variant, 18 ns against glibc's 21 (the 0.5-ulp one costs 160 ns).
LINESIM_UNARY(erf, Sleef_erfd1_u10purec)
LINESIM_UNARY(erfc, Sleef_erfcd1_u15purec)
double atan2(double y, double x) noexcept { return Sleef_atan2d1_u35purec(y, x); }
double hypot(double x, double y) noexcept { return Sleef_hypotd1_u35purec(x, y); }
// SLEEF's pow costs 76 ns against glibc's 10 (measured); CVODE's step-size
// rule takes roots of order 1 to 3 at almost every step (x^1, x^(1/2),
// x^(1/3) after each restart), so these go faster: x^1 and x^2 exactly,
// x^(1/2) as the correctly rounded sqrt, and x^(1/3) (y the double nearest a
// third) as SLEEF's cube root (3.5 ulp; 15 ns), for x > 0 where the two
// agree in meaning (pow(-0, 0.5) is +0, sqrt(-0) is -0).
double pow(double x, double y) noexcept {
  if (y == 1.0) return x;
  if (y == 2.0) return x * x;
  if (x > 0.0) {
    if (y == 0.5) return __builtin_sqrt(x);
    if (y == 1.0 / 3.0) return Sleef_cbrtd1_u35purec(x);
  }
  return Sleef_powd1_u10purec(x, y);
}

void sincos(double x, double* s, double* c) noexcept {
  const Sleef_double_2 r = Sleef_sincosd1_u35purec(x);
  *s = r.x;
  *c = r.y;
}

LINESIM_UNARY_F(sinf, Sleef_sinf1_u35purec)
LINESIM_UNARY_F(cosf, Sleef_cosf1_u35purec)
LINESIM_UNARY_F(tanf, Sleef_tanf1_u35purec)
LINESIM_UNARY_F(asinf, Sleef_asinf1_u35purec)
LINESIM_UNARY_F(acosf, Sleef_acosf1_u35purec)
LINESIM_UNARY_F(atanf, Sleef_atanf1_u35purec)
LINESIM_UNARY_F(expf, Sleef_expf1_u10purec)
LINESIM_UNARY_F(exp2f, Sleef_exp2f1_u35purec)
LINESIM_UNARY_F(logf, Sleef_logf1_u35purec)
LINESIM_UNARY_F(log2f, Sleef_log2f1_u35purec)
float atan2f(float y, float x) noexcept { return Sleef_atan2f1_u35purec(y, x); }
float powf(float x, float y) noexcept { return Sleef_powf1_u10purec(x, y); }
void sincosf(float x, float* s, float* c) noexcept {
  const Sleef_float_2 r = Sleef_sincosf1_u35purec(x);
  *s = r.x;
  *c = r.y;
}

#undef LINESIM_UNARY
#undef LINESIM_UNARY_F

}  // extern "C"
