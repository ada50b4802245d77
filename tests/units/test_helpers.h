#pragma once

// What the unit tests share: access to a unit's variables by name, as the
// master does, and bit-for-bit comparison of its outputs.

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::test_helpers {

inline void SetArray(cosim::Unit& u, const std::string& name, const std::vector<double>& v) {
  u.variables().SetRealArray(*u.variables().Find(name), v);
}

/// Every element of `name` to v.
inline void SetAll(cosim::Unit& u, const std::string& name, double v) {
  u.variables().SetValue(*u.variables().Find(name), cosim::Value{v});
}

/// A real array, or a real scalar as one element.
inline std::vector<double> Get(const cosim::Unit& u, const std::string& name) {
  const auto ref = *u.variables().Find(name);
  if (u.variables().info(ref).type == cosim::VarType::kReal) return {u.variables().GetReal(ref)};
  const auto s = u.variables().GetRealArray(ref);
  return {s.begin(), s.end()};
}

/// Every output (all real), one after the other in table order.
inline std::vector<double> Outputs(const cosim::Unit& u) {
  std::vector<double> out;
  for (const auto& info : u.variables().infos()) {
    if (info.causality != cosim::Causality::kOutput) continue;
    if (info.type == cosim::VarType::kReal) {
      out.push_back(u.variables().GetReal(info.ref));
      continue;
    }
    const auto a = u.variables().GetRealArray(info.ref);
    out.insert(out.end(), a.begin(), a.end());
  }
  return out;
}

/// Equal bit for bit (== would take -0 for 0 and refuse NaN for NaN).
inline bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

/// One entry of a unit's variable table as a test expects it.
struct ExpectedVariable {
  std::string name;
  cosim::Causality causality;
  std::string unit;  // "" leaves the unit unchecked (Boolean, Integer)
  std::size_t size;  // 0: a scalar; N: a Real array of N elements
  std::vector<std::string> depends_on = {};
};

/// The table holds exactly the expected variables, each with its
/// causality, unit of measure, shape and direct dependencies.
inline void ExpectTable(const cosim::Unit& u, const std::vector<ExpectedVariable>& expected) {
  ASSERT_EQ(u.variables().size(), expected.size());
  for (const ExpectedVariable& e : expected) {
    const auto ref = u.variables().Find(e.name);
    ASSERT_TRUE(ref) << e.name;
    const auto& info = u.variables().info(*ref);
    EXPECT_EQ(info.causality, e.causality) << e.name;
    if (!e.unit.empty()) {
      EXPECT_EQ(info.unit, e.unit) << e.name;
    }
    if (e.size > 0) {
      EXPECT_EQ(info.type, cosim::VarType::kRealArray) << e.name;
      EXPECT_EQ(info.size, e.size) << e.name;
    } else {
      EXPECT_NE(info.type, cosim::VarType::kRealArray) << e.name;
    }
    std::vector<std::string> deps;
    for (auto d : info.depends_on) deps.push_back(u.variables().info(d).name);
    EXPECT_EQ(deps, e.depends_on) << e.name;
  }
}

}  // namespace linesim::test_helpers
