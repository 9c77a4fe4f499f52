#pragma once
// A 4-ary min-heap of nodes identified by a dense id, with each id's position kept so that a node
// can be re-keyed or removed in place. The merge loop re-keys every candidate of a new cluster and
// removes the candidates that die; with stale entries left behind instead (a lazy heap), every
// merge would also pop about five of them from the full depth of the heap. The four children of a
// node fill one cache line (16-byte nodes, the array aligned so that each group starts a line),
// so a pop touches half as many lines as in a binary heap.

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "huge_pages.hpp"

namespace primseg::detail {

/// Node: a trivially copyable 16-byte type with a std::uint32_t member `id` below the id count.
/// Before: a strict weak order on nodes, `before(a, b)` when a must come out first.
template <typename Node, typename Before>
class IndexedHeap {
 public:
  static constexpr std::uint32_t kAbsent = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::size_t kArity = 4;
  static_assert(sizeof(Node) * kArity == 64, "four children to a cache line");
  static_assert(std::is_trivially_copyable_v<Node>);

  /// A heap for ids below id_count (at most id_count nodes at once).
  IndexedHeap(std::uint32_t id_count, Before before)
      : storage_(static_cast<Node*>(::operator new(
            (std::size_t{id_count} + kArity - 1) * sizeof(Node), std::align_val_t(64)))),
        nodes_(storage_.get() + kArity - 1),
        before_(std::move(before)) {
    advise_huge_pages(storage_.get(), (std::size_t{id_count} + kArity - 1) * sizeof(Node));
    // The merge loop's first assign() fills every node.
    populate_pages(storage_.get(), (std::size_t{id_count} + kArity - 1) * sizeof(Node));
    reserve_huge_to_fill(position_, id_count);
    position_.assign(id_count, kAbsent);
  }

  /// Replaces the contents by `nodes` (distinct ids) in O(n).
  void assign(const std::vector<Node>& nodes) {
    for (std::size_t i = 0; i < size_; ++i) position_[nodes_[i].id] = kAbsent;
    size_ = nodes.size();
    for (std::size_t i = 0; i < size_; ++i) {
      nodes_[i] = nodes[i];
      position_[nodes[i].id] = to_u32(i);
    }
    for (std::size_t i = size_ / kArity + 1; i-- > 0;)
      if (i < size_) sift_down(i);
  }

  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  bool contains(std::uint32_t id) const { return position_[id] != kAbsent; }
  const Node& top() const { return nodes_[0]; }
  /// The node at a position (0 is the top; the children of p are kArity p + 1 ...).
  const Node& at(std::size_t position) const { return nodes_[position]; }
  /// The position of the node that comes out second if no key changes (the first of the top's
  /// children), or kAbsent below two nodes. O(kArity).
  std::uint32_t runner_up() const {
    if (size_ < 2) return kAbsent;
    const std::size_t end = size_ < kArity + 1 ? size_ : kArity + 1;
    std::size_t best = 1;
    for (std::size_t c = 2; c < end; ++c)
      if (before_(nodes_[c], nodes_[best])) best = c;
    return to_u32(best);
  }

  /// Inserts a node whose id is absent.
  void push(const Node& node) {
    assert(!contains(node.id));
    nodes_[size_] = node;
    position_[node.id] = to_u32(size_);
    sift_up(size_++);
  }

  /// Gives the node with this id (present) a new key, or inserts it if absent. (The order may
  /// read keys outside the node that already changed: the node is placed against its parent and
  /// children, not against its old key.)
  void update(const Node& node) {
    const std::uint32_t p = position_[node.id];
    if (p == kAbsent) return push(node);
    nodes_[p] = node;
    restore(p);
  }

  /// Removes the node with this id if present.
  void erase(std::uint32_t id) {
    const std::uint32_t p = position_[id];
    if (p == kAbsent) return;
    position_[id] = kAbsent;
    const Node last = nodes_[--size_];
    if (p == size_) return;
    place(p, last);
    restore(p);
  }

  void pop() { erase(nodes_[0].id); }

  /// Asks for the cache line of an id's position (a later update or erase reads it first).
  void prefetch(std::uint32_t id) const { __builtin_prefetch(&position_[id]); }
  /// Asks for the cache line of a present id's node (reads its position).
  void prefetch_node(std::uint32_t id) const {
    const std::uint32_t p = position_[id];
    if (p != kAbsent) __builtin_prefetch(&nodes_[p]);
  }

  /// Frees the storage.
  void clear() {
    storage_.reset();
    nodes_ = nullptr;
    size_ = 0;
    std::vector<std::uint32_t>().swap(position_);
  }

 private:
  static std::uint32_t to_u32(std::size_t i) { return static_cast<std::uint32_t>(i); }

  void place(std::size_t p, const Node& node) {
    nodes_[p] = node;
    position_[node.id] = to_u32(p);
  }

  // Moves the node at p up or down to its place.
  void restore(std::size_t p) {
    if (p > 0 && before_(nodes_[p], nodes_[(p - 1) / kArity]))
      sift_up(p);
    else
      sift_down(p);
  }

  void sift_up(std::size_t p) {
    const Node node = nodes_[p];
    while (p > 0) {
      const std::size_t parent = (p - 1) / kArity;
      if (!before_(node, nodes_[parent])) break;
      place(p, nodes_[parent]);
      p = parent;
    }
    place(p, node);
  }

  void sift_down(std::size_t p) {
    const Node node = nodes_[p];
    const std::size_t n = size_;
    for (;;) {
      const std::size_t first = kArity * p + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t end = first + kArity < n ? first + kArity : n;
      // The next level's four groups (one is the path's) while this one is compared.
      for (std::size_t c = first; c < end && kArity * c + 1 < n; ++c)
        __builtin_prefetch(&nodes_[kArity * c + 1]);
      for (std::size_t c = first + 1; c < end; ++c)
        if (before_(nodes_[c], nodes_[best])) best = c;
      if (!before_(nodes_[best], node)) break;
      place(p, nodes_[best]);
      p = best;
    }
    place(p, node);
  }

  struct AlignedDelete {
    void operator()(Node* p) const { ::operator delete(p, std::align_val_t(64)); }
  };
  // Node i at nodes_ + i, with nodes_ three nodes into a 64-byte aligned block: the children
  // 4p + 1 ... 4p + 4 of every node start a cache line.
  std::unique_ptr<Node, AlignedDelete> storage_;
  Node* nodes_ = nullptr;
  std::size_t size_ = 0;
  std::vector<std::uint32_t> position_;  // per id
  Before before_;
};

}  // namespace primseg::detail
