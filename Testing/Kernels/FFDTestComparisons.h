// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDTestComparisons.h
 * @brief What the GoogleTest suites repeat around their comparisons: the typed suite run for float and double,
 * element-wise comparisons of 3-vectors and 3x3 matrices with a tolerance (each a ::testing::AssertionResult that
 * names every entry that failed, with both values, the difference and the tolerance), and the worst error /
 * tolerance ratio a test records. No VTK, no reference: plain C++17 and GoogleTest, for the kernel, filter and
 * GPU tests alike.
 *
 * A comparison is exactly EXPECT_NEAR's, |got - want| <= tolerance (a NaN on either side fails), or, for the
 * exact ones, EXPECT_EQ's got == want. The caller streams what else identifies the case (lattice, point):
 *   ASSERT_TRUE(ffdtest::VectorNear(got, want, tol, "axis")) << "frame " << trial << " point " << p;
 */
#ifndef FFDTestComparisons_h
#define FFDTestComparisons_h

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>

namespace ffdtest
{
/// The precisions the typed suites run in.
using RealTypes = ::testing::Types<float, double>;

/// Declares the typed test suite `Suite`, an empty fixture whose TYPED_TESTs run once with TypeParam = float and
/// once with TypeParam = double.
#define FFD_REAL_TYPED_TEST_SUITE(Suite)                                                                               \
  template <typename Real>                                                                                             \
  class Suite : public ::testing::Test                                                                                 \
  {                                                                                                                    \
  };                                                                                                                   \
  TYPED_TEST_SUITE(Suite, ::ffdtest::RealTypes)

/// Tracks the worst error / tolerance ratio of a test and records it in the XML output (--gtest_output=xml),
/// so the margins can be read without a debugger.
class WorstRatio
{
public:
  explicit WorstRatio(const char* key)
    : Key(key)
  {
  }
  ~WorstRatio() { ::testing::Test::RecordProperty(this->Key, std::to_string(this->Worst)); }
  void Add(double error, double tol) { this->Worst = std::max(this->Worst, error / tol); }

private:
  const char* Key;
  double Worst = 0.0;
};

namespace detail
{
/// Component c of a 3-vector: anything with [] (std::array, a C array or pointer, ffd::Vec3), as a double.
template <typename V>
double Component(const V& v, int c)
{
  return double(v[c]);
}

/// Entry (r, c) of a 3x3 matrix: anything with [r][c] (double[3][3], an array of rows) or a member M[r][c]
/// (ffd::Mat3).
template <typename M>
auto Entry(const M& m, int r, int c) -> decltype(double(m.M[r][c]))
{
  return double(m.M[r][c]);
}
template <typename M>
auto Entry(const M& m, int r, int c) -> decltype(double(m[r][c]))
{
  return double(m[r][c]);
}

/// A tolerance given as a number, or as a function of the index (of (r, c) for matrices).
template <typename Tol, typename... Index>
double ToleranceAt(const Tol& tol, Index... index)
{
  if constexpr (std::is_invocable_v<const Tol&, Index...>)
  {
    return double(tol(index...));
  }
  else
  {
    return double(tol);
  }
}

/// EXPECT_NEAR's test: |got - want| <= tol, false where either is NaN. Records the ratio in `worst`, if given.
inline bool Near(double got, double want, double tol, double& diff, WorstRatio* worst)
{
  diff = std::fabs(got - want);
  if (worst)
  {
    worst->Add(diff, tol);
  }
  return diff <= tol;
}

/// Appends "<where> = got, expected want<relation>" to a failure's message, the numbers to 17 digits.
inline void Mismatch(::testing::AssertionResult& result, bool& failed, const std::string& where, double got,
  double want, const std::string& relation)
{
  std::ostringstream s;
  s << std::setprecision(17) << (failed ? "; " : "") << where << " = " << got << ", expected " << want << relation;
  result << s.str();
  failed = true;
}

inline std::string Index(const char* name, int i)
{
  return std::string(name) + " " + std::to_string(i);
}

inline std::string Index(const char* name, int r, int c)
{
  return std::string(name) + "[" + std::to_string(r) + "][" + std::to_string(c) + "]";
}

inline std::string Within(double tol, double diff)
{
  std::ostringstream s;
  s << std::setprecision(17) << " within " << tol << " (difference " << diff << ")";
  return s.str();
}
} // namespace detail

/**
 * Every component c of two 3-vectors within `tol` (a number, or a function of c) as EXPECT_NEAR compares; on
 * failure the message names each component that is not ("<name> c = got, expected want within tol (difference
 * d)"). `worst`, when given, records each component's error / tolerance.
 */
template <typename A, typename B, typename Tol>
::testing::AssertionResult VectorNear(
  const A& got, const B& want, const Tol& tol, const char* name = "component", WorstRatio* worst = nullptr)
{
  ::testing::AssertionResult result = ::testing::AssertionFailure();
  bool failed = false;
  for (int c = 0; c < 3; ++c)
  {
    const double t = detail::ToleranceAt(tol, c), g = detail::Component(got, c), w = detail::Component(want, c);
    double diff;
    if (!detail::Near(g, w, t, diff, worst))
    {
      detail::Mismatch(result, failed, detail::Index(name, c), g, w, detail::Within(t, diff));
    }
  }
  return failed ? result : ::testing::AssertionSuccess();
}

/// Every component of two 3-vectors equal, as EXPECT_EQ compares (==); the message names each that is not.
template <typename A, typename B>
::testing::AssertionResult VectorEqual(const A& got, const B& want, const char* name = "component")
{
  ::testing::AssertionResult result = ::testing::AssertionFailure();
  bool failed = false;
  for (int c = 0; c < 3; ++c)
  {
    if (!(got[c] == want[c]))
    {
      detail::Mismatch(result, failed, detail::Index(name, c), double(got[c]), double(want[c]), "");
    }
  }
  return failed ? result : ::testing::AssertionSuccess();
}

/**
 * Every entry (r, c) of two 3x3 matrices within `tol` (a number, or a function of (r, c)) as EXPECT_NEAR compares;
 * on failure the message names each entry that is not ("<name>[r][c] = got, expected want within tol (difference
 * d)"). `worst`, when given, records each entry's error / tolerance.
 */
template <typename A, typename B, typename Tol>
::testing::AssertionResult MatrixNear(
  const A& got, const B& want, const Tol& tol, const char* name = "J", WorstRatio* worst = nullptr)
{
  ::testing::AssertionResult result = ::testing::AssertionFailure();
  bool failed = false;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      const double t = detail::ToleranceAt(tol, r, c), g = detail::Entry(got, r, c), w = detail::Entry(want, r, c);
      double diff;
      if (!detail::Near(g, w, t, diff, worst))
      {
        detail::Mismatch(result, failed, detail::Index(name, r, c), g, w, detail::Within(t, diff));
      }
    }
  }
  return failed ? result : ::testing::AssertionSuccess();
}

/// Every entry of two 3x3 matrices equal, as EXPECT_EQ compares (==); the message names each that is not.
template <typename A, typename B>
::testing::AssertionResult MatrixEqual(const A& got, const B& want, const char* name = "J")
{
  ::testing::AssertionResult result = ::testing::AssertionFailure();
  bool failed = false;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      if (!(got.M[r][c] == want.M[r][c]))
      {
        detail::Mismatch(result, failed, detail::Index(name, r, c), double(got.M[r][c]), double(want.M[r][c]), "");
      }
    }
  }
  return failed ? result : ::testing::AssertionSuccess();
}

namespace detail
{
/// compare(got.V, want.V, "V") for the frames' vectors V = X0, S, T, U; fails with the messages of those that fail.
template <typename F, typename Compare>
::testing::AssertionResult EachFrameVector(const F& got, const F& want, const Compare& compare)
{
  ::testing::AssertionResult result = ::testing::AssertionFailure();
  bool failed = false;
  for (const auto& [g, w, name] : { std::make_tuple(&got.X0, &want.X0, "X0"), std::make_tuple(&got.S, &want.S, "S"),
         std::make_tuple(&got.T, &want.T, "T"), std::make_tuple(&got.U, &want.U, "U") })
  {
    const ::testing::AssertionResult vector = compare(*g, *w, name);
    if (!vector)
    {
      result << (failed ? "; " : "") << vector.message();
      failed = true;
    }
  }
  return failed ? result : ::testing::AssertionSuccess();
}
} // namespace detail

/**
 * Two frames (anything with 3-vectors X0, S, T, U, as ffdref::Frame) within `tol` number for number, as
 * EXPECT_NEAR compares; the message names each component that is not ("S 2 = ...").
 */
template <typename F>
::testing::AssertionResult FramesNear(const F& got, const F& want, double tol)
{
  return detail::EachFrameVector(
    got, want, [tol](const auto& g, const auto& w, const char* name) { return VectorNear(g, w, tol, name); });
}

/// Two frames equal number for number, as EXPECT_EQ compares (==); the message names each component that is not.
template <typename F>
::testing::AssertionResult FramesEqual(const F& got, const F& want)
{
  return detail::EachFrameVector(
    got, want, [](const auto& g, const auto& w, const char* name) { return VectorEqual(g, w, name); });
}

/// max(floor, max_rc |m(r, c)|): the size a Jacobian's tolerance scales with.
template <typename M>
double MaxAbsEntry(const M& m, double floor)
{
  double largest = floor;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      largest = std::max(largest, std::fabs(detail::Entry(m, r, c)));
    }
  }
  return largest;
}
} // namespace ffdtest

#endif
