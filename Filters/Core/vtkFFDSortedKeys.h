// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkFFDSortedKeys
 * @brief   keys in increasing order, each with an optional id, found by binary search (private to the core module)
 *
 * The one index of VoxelFFD's sparse sets: a sparse lattice's points and cells by their flat index
 * (vtkFFDFlatIndex), a lattice's points by their LatticeIndex. It owns its entries, sorted once where it is made
 * from them, or views sorted entries that someone else holds (a sparse lattice's point indices, hundreds of MB at
 * 1024^3 voxels, are never copied); copies share the entries. An entry is a key, or a (key, id) pair; the key is
 * an int64 unless another type is named (any with operator<). Equal keys are kept, in the order of their ids:
 * Find() gives the first of them, and FindRepeated() where the keys are not distinct.
 */
#ifndef vtkFFDSortedKeys_h
#define vtkFFDSortedKeys_h

#include "vtkSMPTools.h"
#include "vtkType.h"

#include <algorithm>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

template <typename Id = void, typename Key = vtkTypeInt64>
class vtkFFDSortedKeys
{
public:
  /// An entry: its key alone, or (key, id).
  using Entry = typename std::conditional<std::is_void<Id>::value, Key, std::pair<Key, Id>>::type;

  /// Empty.
  vtkFFDSortedKeys() = default;

  /// Owns `entries`, sorted here (in parallel) unless they already are: by key, equal keys by id.
  explicit vtkFFDSortedKeys(std::vector<Entry> entries)
  {
    auto owned = std::make_shared<std::vector<Entry>>(std::move(entries));
    if (!std::is_sorted(owned->begin(), owned->end()))
    {
      vtkSMPTools::Sort(owned->begin(), owned->end());
    }
    this->First = owned->data();
    this->Last = owned->data() + owned->size();
    this->Owned = std::move(owned);
  }

  /// Views the entries [first, last), sorted by the caller, who keeps them while this is used: nothing is copied.
  vtkFFDSortedKeys(const Entry* first, const Entry* last)
    : First(first)
    , Last(last)
  {
  }

  vtkIdType GetSize() const { return vtkIdType(this->Last - this->First); }
  const Key& GetKey(vtkIdType position) const { return KeyOf(this->First[position]); }
  Id GetId(vtkIdType position) const { return this->First[position].second; }

  /// The position of the first entry whose key is not below `key`: GetSize() where there is none.
  vtkIdType LowerBound(const Key& key) const { return Search(this->First, this->Last, key) - this->First; }

  /**
   * LowerBound(), searched outwards from position `hint` (0 to GetSize()) in steps that double: O(log distance)
   * rather than O(log size) with its cache misses, where successive keys are near each other (a sparse lattice's
   * cells find their points so, voxel after voxel).
   */
  vtkIdType LowerBoundFrom(vtkIdType hint, const Key& key) const
  {
    const Entry* at = this->First + hint;
    std::ptrdiff_t step = 1;
    if (at != this->Last && KeyOf(*at) < key)
    {
      // Forward: *at stays below the key; the bound is in (at, at + step].
      while (step < this->Last - at && KeyOf(at[step]) < key)
      {
        at += step;
        step *= 2;
      }
      return Search(at + 1, at + std::min(step, this->Last - at), key) - this->First;
    }
    // Backward: *at (or the end) is not below the key; the bound is in (at - step, at].
    while (step <= at - this->First && !(KeyOf(at[-step]) < key))
    {
      at -= step;
      step *= 2;
    }
    return Search(step > at - this->First ? this->First : at - step + 1, at, key) - this->First;
  }

  /// The position of the first entry of `key`, or -1 where there is none.
  vtkIdType Find(const Key& key) const
  {
    const vtkIdType at = this->LowerBound(key);
    return at < this->GetSize() && !(key < this->GetKey(at)) ? at : -1;
  }

  /// The id of the first entry of `key`, or -1 where there is none.
  Id FindId(const Key& key) const
  {
    const vtkIdType at = this->Find(key);
    return at < 0 ? Id(-1) : this->GetId(at);
  }

  /// The first position whose key the next entry repeats, or -1 where the keys are distinct.
  vtkIdType FindRepeated() const
  {
    const Entry* at = std::adjacent_find(this->First, this->Last,
      [](const Entry& a, const Entry& b) { return !(KeyOf(a) < KeyOf(b)) && !(KeyOf(b) < KeyOf(a)); });
    return at == this->Last ? -1 : at - this->First;
  }

private:
  static const Key& KeyOf(const Entry& entry)
  {
    if constexpr (std::is_void<Id>::value)
    {
      return entry;
    }
    else
    {
      return entry.first;
    }
  }

  static const Entry* Search(const Entry* first, const Entry* last, const Key& key)
  {
    return std::lower_bound(first, last, key, [](const Entry& entry, const Key& k) { return KeyOf(entry) < k; });
  }

  std::shared_ptr<const std::vector<Entry>> Owned; // null where the entries are viewed
  const Entry* First = nullptr;
  const Entry* Last = nullptr;
};

#endif
