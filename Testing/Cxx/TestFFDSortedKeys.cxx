// SPDX-License-Identifier: BSD-3-Clause
// vtkFFDSortedKeys, the one index of VoxelFFD's sparse sets, against independent references (std::map and linear
// scans): random keys of a fixed seed with duplicates, ids, the hinted search from every hint, the empty set,
// views that copy nothing, copies that share, and (k, j, i) keys at the ends of int.
#include "vtkFFDSortedKeys.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace
{
using Pairs = std::vector<std::pair<vtkTypeInt64, vtkIdType>>;

/// `n` (key, id) pairs, keys drawn from [low, high] (duplicates where the range is small), ids 0 .. n-1 shuffled.
Pairs RandomPairs(std::mt19937_64& random, int n, vtkTypeInt64 low, vtkTypeInt64 high)
{
  std::uniform_int_distribution<vtkTypeInt64> key(low, high);
  std::vector<vtkIdType> ids(n);
  for (int i = 0; i < n; ++i)
  {
    ids[i] = i;
  }
  std::shuffle(ids.begin(), ids.end(), random);
  Pairs pairs(n);
  for (int i = 0; i < n; ++i)
  {
    pairs[i] = { key(random), ids[i] };
  }
  return pairs;
}

/// The position of the first of `keys` not below `key`, by a linear scan.
vtkIdType LinearLowerBound(const std::vector<vtkTypeInt64>& keys, vtkTypeInt64 key)
{
  vtkIdType p = 0;
  while (p < vtkIdType(keys.size()) && keys[p] < key)
  {
    ++p;
  }
  return p;
}
} // namespace

TEST(FFDSortedKeys, EmptySet)
{
  const std::vector<vtkTypeInt64> none;
  const vtkFFDSortedKeys<vtkIdType> empty;
  const vtkFFDSortedKeys<vtkIdType> owned{ Pairs() };
  const vtkFFDSortedKeys<> viewed(none.data(), none.data());
  for (const vtkTypeInt64 key : { vtkTypeInt64(-1), vtkTypeInt64(0), vtkTypeInt64(7) })
  {
    EXPECT_EQ(empty.GetSize(), 0);
    EXPECT_EQ(empty.Find(key), -1);
    EXPECT_EQ(empty.FindId(key), -1);
    EXPECT_EQ(empty.LowerBound(key), 0);
    EXPECT_EQ(empty.LowerBoundFrom(0, key), 0);
    EXPECT_EQ(owned.GetSize(), 0);
    EXPECT_EQ(owned.FindId(key), -1);
    EXPECT_EQ(owned.LowerBoundFrom(0, key), 0);
    EXPECT_EQ(viewed.Find(key), -1);
    EXPECT_EQ(viewed.LowerBoundFrom(0, key), 0);
  }
  EXPECT_EQ(empty.FindRepeated(), -1);
  EXPECT_EQ(viewed.FindRepeated(), -1);
}

// Built from unsorted (key, id) pairs: sorted by key then id, and each key found with its smallest id (the
// duplicates policy), against a std::map of each key's smallest id.
TEST(FFDSortedKeys, FindAgainstMap)
{
  std::mt19937_64 random(31);
  for (const vtkTypeInt64 range : { vtkTypeInt64(50), vtkTypeInt64(5000), vtkTypeInt64(1) << 40 })
  {
    const Pairs pairs = RandomPairs(random, 1000, -range, range);
    std::map<vtkTypeInt64, vtkIdType> smallest;
    for (const auto& pair : pairs)
    {
      auto at = smallest.emplace(pair.first, pair.second).first;
      at->second = std::min(at->second, pair.second);
    }
    const vtkFFDSortedKeys<vtkIdType> keys(pairs);
    ASSERT_EQ(keys.GetSize(), vtkIdType(pairs.size()));
    for (vtkIdType p = 1; p < keys.GetSize(); ++p)
    {
      ASSERT_TRUE(
        std::make_pair(keys.GetKey(p - 1), keys.GetId(p - 1)) < std::make_pair(keys.GetKey(p), keys.GetId(p)));
    }
    // Every key of the set, and keys between, before and after them.
    std::vector<vtkTypeInt64> queries{ -range - 1, range + 1, std::numeric_limits<vtkTypeInt64>::min(),
      std::numeric_limits<vtkTypeInt64>::max() };
    for (const auto& pair : pairs)
    {
      queries.insert(queries.end(), { pair.first - 1, pair.first, pair.first + 1 });
    }
    for (const vtkTypeInt64 key : queries)
    {
      const auto expected = smallest.find(key);
      const vtkIdType position = keys.Find(key);
      if (expected == smallest.end())
      {
        EXPECT_EQ(position, -1) << key;
        EXPECT_EQ(keys.FindId(key), -1) << key;
        continue;
      }
      ASSERT_GE(position, 0) << key;
      EXPECT_EQ(keys.GetKey(position), key);
      EXPECT_TRUE(position == 0 || keys.GetKey(position - 1) < key) << "not the first entry of " << key;
      EXPECT_EQ(keys.FindId(key), expected->second) << key;
    }
  }
}

// FindRepeated(): the first position whose key the next entry repeats, against a linear scan; -1 when distinct.
TEST(FFDSortedKeys, Repeated)
{
  std::mt19937_64 random(32);
  for (int trial = 0; trial < 20; ++trial)
  {
    const vtkFFDSortedKeys<vtkIdType> keys(RandomPairs(random, 40, 0, 2000));
    vtkIdType expected = -1;
    for (vtkIdType p = 0; p + 1 < keys.GetSize() && expected < 0; ++p)
    {
      expected = keys.GetKey(p) == keys.GetKey(p + 1) ? p : -1;
    }
    EXPECT_EQ(keys.FindRepeated(), expected);
    if (expected >= 0)
    {
      EXPECT_LT(keys.GetId(expected), keys.GetId(expected + 1)); // equal keys in the order of their ids
    }
  }
  const vtkFFDSortedKeys<int> distinct(std::vector<std::pair<vtkTypeInt64, int>>{ { 5, 0 }, { 3, 1 }, { 9, 2 } });
  EXPECT_EQ(distinct.FindRepeated(), -1);
  const vtkFFDSortedKeys<int> twice(std::vector<std::pair<vtkTypeInt64, int>>{ { 5, 2 }, { 3, 1 }, { 5, 0 } });
  ASSERT_EQ(twice.FindRepeated(), 1);
  EXPECT_EQ(twice.GetId(1), 0);
  EXPECT_EQ(twice.GetId(2), 2);
}

// The hinted search from every hint (0 to the size, the end included) to keys before, at, between, among
// duplicates and after the set's, against a linear scan: the same position as LowerBound() whatever the hint.
TEST(FFDSortedKeys, LowerBoundFromEveryHint)
{
  std::mt19937_64 random(33);
  std::vector<vtkTypeInt64> sorted;
  for (const auto& pair : RandomPairs(random, 300, -400, 400))
  {
    sorted.push_back(pair.first);
  }
  std::sort(sorted.begin(), sorted.end());
  const vtkFFDSortedKeys<> keys(sorted.data(), sorted.data() + sorted.size());
  ASSERT_NE(keys.FindRepeated(), -1); // duplicates, and gaps, in the range
  for (vtkTypeInt64 key = -403; key <= 403; ++key)
  {
    const vtkIdType expected = LinearLowerBound(sorted, key);
    ASSERT_EQ(keys.LowerBound(key), expected) << key;
    for (vtkIdType hint = 0; hint <= keys.GetSize(); ++hint)
    {
      ASSERT_EQ(keys.LowerBoundFrom(hint, key), expected) << "key " << key << " from hint " << hint;
    }
  }
}

// Far from the hint, both ways, over distinct keys as a sparse lattice's points are: the galloping steps cover
// every distance up to the whole set.
TEST(FFDSortedKeys, LowerBoundFromFar)
{
  std::mt19937_64 random(34);
  std::vector<vtkTypeInt64> sorted;
  for (const auto& pair : RandomPairs(random, 20000, 0, vtkTypeInt64(1) << 36))
  {
    sorted.push_back(pair.first);
  }
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  const vtkFFDSortedKeys<> keys(sorted.data(), sorted.data() + sorted.size());
  ASSERT_EQ(keys.FindRepeated(), -1);
  std::uniform_int_distribution<vtkIdType> position(0, keys.GetSize());
  for (int trial = 0; trial < 20000; ++trial)
  {
    const vtkIdType hint = position(random), target = position(random);
    const vtkTypeInt64 key = target == keys.GetSize() ? sorted.back() + 1 : sorted[target] - (trial % 2);
    ASSERT_EQ(
      keys.LowerBoundFrom(hint, key), vtkIdType(std::lower_bound(sorted.begin(), sorted.end(), key) - sorted.begin()))
      << "key " << key << " from hint " << hint;
  }
}

// A view reads the caller's keys in place (nothing copied); owned keys are shared by copies, which outlive the
// original; keys already sorted are kept as they are.
TEST(FFDSortedKeys, ViewsAndCopies)
{
  const std::vector<vtkTypeInt64> sorted{ -3, 0, 4, 4, 10 };
  const vtkFFDSortedKeys<> view(sorted.data(), sorted.data() + sorted.size());
  EXPECT_EQ(&view.GetKey(0), sorted.data());
  EXPECT_EQ(view.Find(4), 2);
  EXPECT_EQ(view.Find(5), -1);

  vtkFFDSortedKeys<> copy;
  {
    const vtkFFDSortedKeys<> owned(std::vector<vtkTypeInt64>{ 10, 4, -3, 0, 4 });
    copy = owned;
    EXPECT_EQ(&copy.GetKey(0), &owned.GetKey(0)); // shared, not copied
  }
  ASSERT_EQ(copy.GetSize(), 5);
  for (vtkIdType p = 0; p < 5; ++p)
  {
    EXPECT_EQ(copy.GetKey(p), sorted[p]);
  }
  const vtkFFDSortedKeys<> moved(std::move(copy));
  EXPECT_EQ(moved.Find(-3), 0);
  EXPECT_EQ(moved.Find(10), 4);
}

// Keys other than int64: (k, j, i) triples at the ends of int, which no flat index could hold, against a std::map.
TEST(FFDSortedKeys, TripleKeys)
{
  using Key = std::array<int, 3>;
  std::mt19937_64 random(35);
  const int values[] = { INT_MIN, INT_MIN + 1, -1, 0, 1, INT_MAX - 1, INT_MAX };
  std::uniform_int_distribution<int> pick(0, 6);
  std::vector<std::pair<Key, vtkIdType>> pairs;
  std::map<Key, vtkIdType> smallest;
  for (vtkIdType id = 0; id < 500; ++id)
  {
    const Key key{ values[pick(random)], values[pick(random)], values[pick(random)] };
    pairs.emplace_back(key, id);
    smallest.emplace(key, id); // ids increase: the first is the smallest
  }
  const vtkFFDSortedKeys<vtkIdType, Key> keys(pairs);
  for (const int k : values)
  {
    for (const int j : values)
    {
      for (const int i : values)
      {
        const auto expected = smallest.find(Key{ k, j, i });
        EXPECT_EQ(keys.FindId(Key{ k, j, i }), expected == smallest.end() ? -1 : expected->second);
      }
    }
  }
}
