// The process's math functions and the provenance a result carries.
#include "platform/platform.h"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <sleef.h>

#include <cmath>
#include <cstring>
#include <random>

#include "platform/provenance.h"
#include "platform/sha256.h"

namespace linesim::platform {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Guards: an executable that lets glibc's CPU-dispatched libm in (a link
// order, a missing object), which makes every result machine-dependent.
TEST(DeterministicMath, EveryLibraryBindsToSleefNotLibm) {
  EXPECT_TRUE(DeterministicMathBound());
  EXPECT_NE(MathLibrary().find("sleef"), std::string::npos) << MathLibrary();
  // What a shared library (ODE, SUNDIALS) gets: the global scope's symbol.
  using Unary = double (*)(double);
  using Binary = double (*)(double, double);
  const auto sin_global = reinterpret_cast<Unary>(dlsym(RTLD_DEFAULT, "sin"));
  const auto pow_global = reinterpret_cast<Binary>(dlsym(RTLD_DEFAULT, "pow"));
  const auto atan2_global = reinterpret_cast<Binary>(dlsym(RTLD_DEFAULT, "atan2"));
  ASSERT_NE(sin_global, nullptr);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  for (int i = 0; i < 100000; ++i) {
    const double x = u(rng), y = u(rng);
    ASSERT_TRUE(SameBits(sin_global(x), Sleef_sind1_u35purec(x))) << x;
    ASSERT_TRUE(SameBits(std::sin(x), Sleef_sind1_u35purec(x))) << x;
    ASSERT_TRUE(SameBits(pow_global(std::abs(x), y / 8), Sleef_powd1_u10purec(std::abs(x), y / 8)));
    ASSERT_TRUE(SameBits(atan2_global(y, x), Sleef_atan2d1_u35purec(y, x)));
  }
}

// Guards: an interposed function less accurate than promised (SLEEF's
// bounds: 3.5 ulp for sin, log, atan2; 1 ulp for exp), checked against
// values known to 20 digits (sin 1, e, ln 2, atan2(1, 1) = pi/4).
TEST(DeterministicMath, ValuesWithinOneUlp) {
  auto ulps = [](double got, double want) {
    return std::abs(got - want) / (std::nextafter(want, 2 * want) - want);
  };
  EXPECT_LE(ulps(std::sin(1.0), 0.84147098480789650665), 3.5);
  EXPECT_LE(ulps(std::exp(1.0), 2.71828182845904523536), 1.0);
  EXPECT_LE(ulps(std::log(2.0), 0.69314718055994530942), 3.5);
  EXPECT_LE(ulps(std::atan2(1.0, 1.0), 0.78539816339744830962), 3.5);
  EXPECT_EQ(std::pow(2.0, 10.0), 1024.0);
  EXPECT_EQ(std::pow(0.3, 1.0), 0.3);
  EXPECT_EQ(std::pow(0.3, 2.0), 0.3 * 0.3);
  EXPECT_TRUE(std::isnan(std::log(-1.0)));
  EXPECT_EQ(std::exp(-1000.0), 0.0);
}

// FIPS 180-2, appendix B.1 and the empty message.
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

// Guards: a result that does not say what made it.
TEST(Provenance, NamesBuildMachineAndInputs) {
  RecordDispatch("example", "sse2 kernels");
  const auto j = ProvenanceJson("abc123", 7);
  for (const char* key : {"linesim_version", "commit", "compiler", "build_type", "cpu_model",
                          "cpu_features", "dispatch", "scenario_sha256", "seed"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["seed"], 7);
  EXPECT_EQ(j["scenario_sha256"], "abc123");
  EXPECT_EQ(j["dispatch"]["example"], "sse2 kernels");
  EXPECT_NE(j["dispatch"]["libm"].get<std::string>().find("sleef"), std::string::npos);
  EXPECT_NE(VersionLine().find(Version()), std::string::npos);
}

}  // namespace
}  // namespace linesim::platform
