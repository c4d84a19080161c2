// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file vtkFFDGroupedIds.h
 * @brief Ids grouped by an integer key with a counting sort (private to the Sensitivity module): points by cell,
 * a lattice's corners by node, a chunk's terms by control point. The same grouping for any number of threads.
 */
#ifndef vtkFFDGroupedIds_h
#define vtkFFDGroupedIds_h

#include "vtkType.h"

#include <algorithm>
#include <vector>

// Ids grouped by key, in increasing id within each group: the ids of key k are Order[Start[k]] ..
// Order[Start[k + 1] - 1]; negative keys are left out. A counting sort: the same grouping for any number of
// threads. `keys` is at least 1 + the largest key.
struct vtkFFDGroupedIds
{
  std::vector<vtkIdType> Start, Order;

  template <typename Key>
  vtkFFDGroupedIds(const std::vector<Key>& keyOf, std::size_t keys)
    : Start(keys + 1, 0)
  {
    for (Key k : keyOf)
    {
      this->Start[std::size_t(k) + 1] += k >= 0 ? 1 : 0;
    }
    for (std::size_t k = 0; k < keys; ++k)
    {
      this->Start[k + 1] += this->Start[k];
    }
    this->Order.resize(this->Start[keys]);
    std::vector<vtkIdType> next(this->Start.begin(), this->Start.end() - 1);
    for (std::size_t id = 0; id < keyOf.size(); ++id)
    {
      if (keyOf[id] >= 0)
      {
        this->Order[next[keyOf[id]]++] = vtkIdType(id);
      }
    }
  }
  /// The ids bound to a cell (keys 0 .. largest).
  explicit vtkFFDGroupedIds(const std::vector<int>& cellOf)
    : vtkFFDGroupedIds(
        cellOf, cellOf.empty() ? 0 : 1 + std::size_t(std::max(0, *std::max_element(cellOf.begin(), cellOf.end()))))
  {
  }
  int Groups() const { return int(this->Start.size()) - 1; }
};

#endif
