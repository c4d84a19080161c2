// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file FFDExactSum.h
 * @brief A sum of doubles that does not depend on their order: kept exactly as non-overlapping partials
 * (Shewchuk's expansion, as Python's math.fsum keeps it) and rounded once, correctly, at the end.
 *
 * What makes a frame computed from a mesh's points the same bit for bit however the points are ordered or split
 * among processes: each process sums its points, the partials of all processes are added together, and the
 * correctly rounded value of the exact sum is the same.
 */
#ifndef FFDExactSum_h
#define FFDExactSum_h

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace ffd
{

class ExactSum
{
public:
  /// Adds x exactly (finite values; an infinite or NaN one makes the value non-finite).
  void Add(double x)
  {
    std::size_t kept = 0;
    for (double y : this->Partials)
    {
      if (std::fabs(x) < std::fabs(y))
      {
        std::swap(x, y);
      }
      const double high = x + y;
      const double low = y - (high - x);
      if (low != 0.0)
      {
        this->Partials[kept++] = low;
      }
      x = high;
    }
    this->Partials.resize(kept);
    this->Partials.push_back(x);
  }

  /// The partials: their exact sum is the sum of every value added. Another ExactSum adds them with Add().
  const std::vector<double>& GetPartials() const { return this->Partials; }

  /// The exact sum rounded to the nearest double (ties to even).
  double Value() const
  {
    std::size_t n = this->Partials.size();
    if (n == 0)
    {
      return 0.0;
    }
    double high = this->Partials[--n];
    double low = 0.0;
    while (n > 0)
    {
      const double x = high;
      const double y = this->Partials[--n];
      high = x + y;
      low = y - (high - x);
      if (low != 0.0)
      {
        break;
      }
    }
    // The rounding of high + low is half-way only in appearance when the partials below low have its sign.
    if (n > 0 && ((low < 0.0 && this->Partials[n - 1] < 0.0) || (low > 0.0 && this->Partials[n - 1] > 0.0)))
    {
      const double twice = 2.0 * low;
      const double x = high + twice;
      if (twice == x - high)
      {
        high = x;
      }
    }
    return high;
  }

private:
  std::vector<double> Partials; // non-overlapping, increasing magnitude
};

} // namespace ffd

#endif
