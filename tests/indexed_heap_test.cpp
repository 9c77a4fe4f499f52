// The candidate queue against an ordered set doing the same operations.
#include "indexed_heap.hpp"

#include <gtest/gtest.h>

#include <iterator>
#include <random>
#include <set>

namespace primseg::detail {
namespace {

struct Node {
  double key;
  std::uint32_t id;
};

struct Before {
  bool operator()(const Node& a, const Node& b) const {
    return a.key != b.key ? a.key < b.key : a.id < b.id;
  }
};

TEST(IndexedHeap, PopsInOrderAndNamesTheRunnerUpThroughRandomPushesUpdatesAndErasures) {
  constexpr std::uint32_t kIds = 2000;
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::uint32_t> any_id(0, kIds - 1);
  // Few distinct keys: many ties, settled by id.
  std::uniform_int_distribution<int> any_key(0, 50);
  IndexedHeap<Node, Before> heap(kIds, Before{});
  std::set<std::pair<double, std::uint32_t>> reference;
  std::vector<double> key_of(kIds, -1);

  std::vector<Node> initial;
  for (std::uint32_t id = 0; id < kIds; id += 3) {
    initial.push_back({double(any_key(rng)), id});
    key_of[id] = initial.back().key;
    reference.insert({initial.back().key, id});
  }
  heap.assign(initial);
  for (int step = 0; step < 200000; ++step) {
    const std::uint32_t id = any_id(rng);
    switch (rng() % 4) {
      case 0:  // update or insert
      case 1: {
        const double key = any_key(rng);
        if (key_of[id] >= 0) reference.erase({key_of[id], id});
        heap.update({key, id});
        key_of[id] = key;
        reference.insert({key, id});
        break;
      }
      case 2:
        heap.erase(id);
        if (key_of[id] >= 0) reference.erase({key_of[id], id});
        key_of[id] = -1;
        break;
      default:
        if (!reference.empty()) {
          ASSERT_FALSE(heap.empty());
          const auto [key, top] = *reference.begin();
          ASSERT_EQ(heap.top().id, top);
          ASSERT_EQ(heap.top().key, key);
          // What comes out next, unless keys change.
          if (reference.size() < 2)
            ASSERT_EQ(heap.runner_up(), heap.kAbsent);
          else
            ASSERT_EQ(heap.at(heap.runner_up()).id, std::next(reference.begin())->second);
          heap.pop();
          reference.erase(reference.begin());
          key_of[top] = -1;
        }
    }
    ASSERT_EQ(heap.size(), reference.size());
    ASSERT_EQ(heap.contains(id), key_of[id] >= 0);
  }
  while (!reference.empty()) {
    ASSERT_EQ(heap.top().id, reference.begin()->second);
    heap.pop();
    reference.erase(reference.begin());
  }
  EXPECT_TRUE(heap.empty());
}

}  // namespace
}  // namespace primseg::detail
