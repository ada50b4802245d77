// Which libm functions platform/deterministic_math.cc must define: every one
// that linesim's binaries and the libraries they load import, found from
// the binaries themselves (nm on each, ldd for what each loads), so that a
// new import (a library update, a new call in a unit) fails here instead of
// letting glibc's CPU-dependent code back in.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <sleef.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

// The output of a shell command (the paths below come from the build).
std::string Output(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return "";
  std::string out;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe.get())) {
    out.append(buffer, n);
  }
  return out;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

// Symbol names (version suffix dropped) of `nm -D` with `option`.
std::set<std::string> DynamicSymbols(const std::string& file, const std::string& option) {
  std::set<std::string> names;
  for (const std::string& line : Lines(Output("nm -D " + option + " '" + file + "' 2>/dev/null"))) {
    std::string name = line.substr(line.find_last_of(' ') + 1);
    name = name.substr(0, name.find('@'));
    names.insert(name);
  }
  return names;
}

// The shared libraries `file` loads (ldd), by path.
std::vector<std::string> LoadedLibraries(const std::string& file) {
  std::vector<std::string> out;
  for (const std::string& line : Lines(Output("ldd '" + file + "' 2>/dev/null"))) {
    const auto arrow = line.find("=> /");
    if (arrow == std::string::npos) continue;
    const std::string rest = line.substr(arrow + 3);
    out.push_back(rest.substr(0, rest.find(' ')));
  }
  return out;
}

// The linesim binaries whose math must be SLEEF's: the command line, the
// Python module and the runtime of exported FMUs (bound when linesim loads
// one; a foreign master keeps its own libm, docs/architecture.md).
std::vector<std::string> Binaries() {
  std::vector<std::string> out{LINESIM_CLI, LINESIM_FMU_RUNTIME};
#ifdef LINESIM_PYTHON_MODULE
  out.push_back(LINESIM_PYTHON_MODULE);
#endif
  return out;
}

// The names deterministic_math.list exports (the functions the .cc defines).
std::set<std::string> BoundFunctions() {
  std::ifstream in(LINESIM_SOURCE_DIR "/platform/deterministic_math.list");
  std::stringstream text;
  text << in.rdbuf();
  std::string list = text.str();
  list = list.substr(list.find('{') + 1);
  list = list.substr(0, list.find('}'));
  std::set<std::string> names;
  std::string name;
  for (char c : list) {
    if (c == ';') {
      names.insert(name);
      name.clear();
    } else if (!std::isspace(static_cast<unsigned char>(c))) {
      name += c;
    }
  }
  return names;
}

// libm functions whose result IEEE 754 (or C's definition) fixes exactly,
// so every CPU gives the same bits whichever variant glibc picks: square
// root (correctly rounded), rounding to integers, exact remainders,
// scaling and splitting by powers of two, neighbours, min and max, and the
// rounding-mode controls.
const std::set<std::string> kExact = {
    "sqrt",       "sqrtf",      "sqrtl",         "fabs",         "fabsf",         "copysign",
    "copysignf",  "floor",      "floorf",        "ceil",         "ceilf",         "trunc",
    "truncf",     "round",      "roundf",        "lround",       "lroundf",       "llround",
    "llroundf",   "rint",       "rintf",         "lrint",        "lrintf",        "llrint",
    "nearbyint",  "nearbyintf", "fmod",          "fmodf",        "remainder",     "remainderf",
    "remquo",     "ldexp",      "ldexpf",        "scalbn",       "scalbnf",       "frexp",
    "frexpf",     "frexpl",     "modf",          "modff",        "modfl",         "ilogb",
    "logb",       "nextafter",  "nextafterf",    "nextafterl",   "nexttoward",    "fmin",
    "fminf",      "fmax",       "fmaxf",         "fdim",         "fma",           "fmaf",
    "fegetround", "fesetround", "feclearexcept", "fetestexcept", "feraiseexcept", "fegetenv",
    "fesetenv",   "__finite",   "__isnan",       "__isinf",      "__signbit",     "__fpclassify"};

// Guards issue 37: FCL's erfc and the PX4Flow model's erf came from glibc
// (erf calls glibc's CPU-dispatched exp inside libm: other bits on FMA and
// non-FMA CPUs). Every libm import of every binary and library must be
// bound or exact.
TEST(DeterministicMath, EveryLibmImportOfEveryBinaryAndLibraryIsBoundOrExact) {
#ifdef LINESIM_SANITIZED
  // The claim is the Release binaries'. A sanitizer build links clang's
  // runtime into each binary, whose interceptors (lgamma's signgam, logl,
  // nan) are imports of their own.
  GTEST_SKIP() << "checks the Release binaries' imports, not the sanitizer runtime's";
#endif
  std::set<std::string> files;
  std::string libm;
  for (const std::string& binary : Binaries()) {
    files.insert(binary);
    for (const std::string& library : LoadedLibraries(binary)) {
      files.insert(library);
      if (library.find("/libm.so") != std::string::npos) libm = library;
    }
  }
  ASSERT_FALSE(libm.empty()) << "ldd shows no libm";
  const std::set<std::string> libm_functions = DynamicSymbols(libm, "--defined-only");
  ASSERT_GT(libm_functions.size(), 300u) << libm;
  const std::set<std::string> bound = BoundFunctions();
  std::map<std::string, std::set<std::string>> imported;  // function -> importers
  for (const std::string& file : files) {
    if (file == libm) continue;
    const std::set<std::string> undefined = DynamicSymbols(file, "--undefined-only");
    ASSERT_FALSE(undefined.empty()) << "nm read nothing of " << file;
    for (const std::string& name : undefined) {
      if (libm_functions.count(name)) imported[name].insert(file);
    }
  }
  // What was found, so that the test cannot pass by reading nothing: FCL's
  // erfc, ODE's atan2.
  ASSERT_TRUE(imported.count("erfc")) << "FCL's erfc not found: did nm or ldd fail?";
  ASSERT_TRUE(imported.count("atan2"));
  for (const auto& [name, importers] : imported) {
    if (bound.count(name) || kExact.count(name)) continue;
    std::string who;
    for (const auto& f : importers) who += " " + f;
    ADD_FAILURE() << name << " is imported from libm by" << who
                  << ": define it in platform/deterministic_math.cc with SLEEF (and list it "
                     "in deterministic_math.list), or, if IEEE 754 defines its result exactly, "
                     "add it to kExact here";
  }
}

// Guards the binding itself: every exported name resolves, in the scope
// shared libraries bind through, to the executable's definition, and the
// newly bound functions give SLEEF's bits.
TEST(DeterministicMath, EveryListedFunctionResolvesToTheExecutable) {
  for (const std::string& name : BoundFunctions()) {
    void* address = dlsym(RTLD_DEFAULT, name.c_str());
    Dl_info info{};
    ASSERT_NE(address, nullptr) << name;
    ASSERT_NE(dladdr(address, &info), 0) << name;
    EXPECT_EQ(std::string(info.dli_fname).find("libm.so"), std::string::npos)
        << name << " resolves to " << info.dli_fname;
  }
  using Unary = double (*)(double);
  using Binary = double (*)(double, double);
  const auto erf_global = reinterpret_cast<Unary>(dlsym(RTLD_DEFAULT, "erf"));
  const auto erfc_global = reinterpret_cast<Unary>(dlsym(RTLD_DEFAULT, "erfc"));
  const auto hypot_global = reinterpret_cast<Binary>(dlsym(RTLD_DEFAULT, "hypot"));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-6.0, 6.0);
  const auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  for (int i = 0; i < 20000; ++i) {
    const double x = u(rng), y = u(rng);
    ASSERT_TRUE(same(erf_global(x), Sleef_erfd1_u10purec(x))) << x;
    ASSERT_TRUE(same(std::erf(x), Sleef_erfd1_u10purec(x))) << x;
    ASSERT_TRUE(same(erfc_global(x), Sleef_erfcd1_u15purec(x))) << x;
    ASSERT_TRUE(same(hypot_global(x, y), Sleef_hypotd1_u35purec(x, y))) << x << " " << y;
  }
  // Within their bounds (1, 1.5 and 3.5 ulp) of values known to 20
  // digits: erf(0.5), erfc(2), hypot(3, 4) = 5.
  EXPECT_NEAR(std::erf(0.5), 0.52049987781304653768, 1.2e-16);
  EXPECT_NEAR(std::erfc(2.0), 0.0046777349810472658379, 1.4e-18);
  EXPECT_NEAR(std::hypot(3.0, 4.0), 5.0, 3.5 * 8.9e-16);
}

}  // namespace
