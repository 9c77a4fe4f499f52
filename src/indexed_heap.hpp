#pragma once
// A 4-ary min-heap of nodes identified by a dense id, with each id's position kept so that a node
// can be re-keyed or removed in place. The merge loop re-keys every candidate of a new cluster and
// removes the candidates that die; with stale entries left behind instead (a lazy heap), every
// merge would also pop about five of them from the full depth of the heap. Four children share a
// cache line (16-byte nodes), so a pop touches half as many lines as in a binary heap.

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace primseg::detail {

/// Node: a trivially copyable type with a std::uint32_t member `id` below the id count.
/// Before: a strict weak order on nodes, `before(a, b)` when a must come out first.
template <typename Node, typename Before>
class IndexedHeap {
 public:
  static constexpr std::uint32_t kAbsent = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::size_t kArity = 4;

  IndexedHeap(std::uint32_t id_count, Before before)
      : position_(id_count, kAbsent), before_(std::move(before)) {}

  /// Replaces the contents by `nodes` (distinct ids) in O(n).
  void assign(std::vector<Node> nodes) {
    for (const Node& node : nodes_) position_[node.id] = kAbsent;
    nodes_ = std::move(nodes);
    for (std::size_t i = 0; i < nodes_.size(); ++i) position_[nodes_[i].id] = to_u32(i);
    for (std::size_t i = nodes_.size() / kArity + 1; i-- > 0;)
      if (i < nodes_.size()) sift_down(i);
  }

  bool empty() const { return nodes_.empty(); }
  std::size_t size() const { return nodes_.size(); }
  bool contains(std::uint32_t id) const { return position_[id] != kAbsent; }
  const Node& top() const { return nodes_.front(); }
  /// The node at a position (0 is the top; the children of p are kArity p + 1 ...).
  const Node& at(std::size_t position) const { return nodes_[position]; }

  /// Inserts a node whose id is absent.
  void push(const Node& node) {
    assert(!contains(node.id));
    nodes_.push_back(node);
    position_[node.id] = to_u32(nodes_.size() - 1);
    sift_up(nodes_.size() - 1);
  }

  /// Gives the node with this id (present) a new key, or inserts it if absent.
  void update(const Node& node) {
    const std::uint32_t p = position_[node.id];
    if (p == kAbsent) return push(node);
    const bool earlier = before_(node, nodes_[p]);
    nodes_[p] = node;
    if (earlier)
      sift_up(p);
    else
      sift_down(p);
  }

  /// Removes the node with this id if present.
  void erase(std::uint32_t id) {
    const std::uint32_t p = position_[id];
    if (p == kAbsent) return;
    position_[id] = kAbsent;
    const Node last = nodes_.back();
    nodes_.pop_back();
    if (p == nodes_.size()) return;
    const bool earlier = before_(last, nodes_[p]);
    nodes_[p] = last;
    position_[last.id] = p;
    if (earlier)
      sift_up(p);
    else
      sift_down(p);
  }

  void pop() { erase(nodes_.front().id); }

  /// Frees the storage.
  void clear() {
    std::vector<Node>().swap(nodes_);
    std::vector<std::uint32_t>().swap(position_);
  }

 private:
  static std::uint32_t to_u32(std::size_t i) { return static_cast<std::uint32_t>(i); }

  void place(std::size_t p, const Node& node) {
    nodes_[p] = node;
    position_[node.id] = to_u32(p);
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
    const std::size_t n = nodes_.size();
    for (;;) {
      const std::size_t first = kArity * p + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t end = first + kArity < n ? first + kArity : n;
      for (std::size_t c = first + 1; c < end; ++c)
        if (before_(nodes_[c], nodes_[best])) best = c;
      if (!before_(nodes_[best], node)) break;
      place(p, nodes_[best]);
      p = best;
    }
    place(p, node);
  }

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> position_;  // per id
  Before before_;
};

}  // namespace primseg::detail
