#pragma once
// Items 0, 1, ..., count − 1 produced on the caller's thread and one helper thread, and taken by
// the caller in order: the caller consumes item i (work that must stay on its thread, such as a
// callback into Python) while the helper produces the next ones, and produces them itself while it
// would otherwise wait. Each item is a function of its index alone, so what the caller takes does
// not depend on which thread produced it.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "parallel.hpp"

namespace primseg::detail {

template <typename T>
class OrderedPipeline {
 public:
  /// produce(i, stop) makes item i; it may give up early (throw) once `stop` is set, which the
  /// destructor does. At most `lookahead` (>= 1) items from the next one to take on are produced
  /// or in production at once, which bounds the memory of items made ahead. With `helper` false
  /// (or when the system refuses a thread), take() produces each item itself.
  OrderedPipeline(std::size_t count, std::size_t lookahead, bool helper,
                  std::function<T(std::size_t, const std::atomic<bool>&)> produce)
      : produce_(std::move(produce)),
        lookahead_(lookahead < 1 ? 1 : lookahead),
        items_(count),
        errors_(count) {
    if (!helper || count == 0) return;
    helper_.reserve(1);
    start_threads(helper_, 2, [this](unsigned) { help(); });
  }

  OrderedPipeline(const OrderedPipeline&) = delete;
  OrderedPipeline& operator=(const OrderedPipeline&) = delete;

  /// Stops the helper once its current item is made or given up, and waits for it.
  ~OrderedPipeline() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;  // under the lock, so that a helper about to wait sees it
    }
    changed_.notify_all();
    for (std::thread& helper : helper_) helper.join();
  }

  /// The next item in order; rethrows what producing it threw. Throws std::out_of_range once all
  /// count items are taken.
  T take() {
    std::unique_lock lock(mutex_);
    const std::size_t wanted = next_take_;
    if (wanted >= items_.size()) throw std::out_of_range("OrderedPipeline::take: no item left");
    while (!done(wanted)) {
      std::size_t index;
      if (claim(index)) {
        produce_unlocked(index, lock);
      } else {
        changed_.wait(lock);
      }
    }
    ++next_take_;
    changed_.notify_all();  // room for one more item ahead
    if (errors_[wanted]) std::rethrow_exception(errors_[wanted]);
    T item = std::move(*items_[wanted]);
    items_[wanted].reset();
    return item;
  }

 private:
  // Under the lock: whether item `index` is made (or failed).
  bool done(std::size_t index) const { return items_[index].has_value() || errors_[index]; }

  // Under the lock: the next index to produce, if one is left within the lookahead.
  bool claim(std::size_t& index) {
    if (next_claim_ >= items_.size() || next_claim_ >= next_take_ + lookahead_) return false;
    index = next_claim_++;
    return true;
  }

  // Produces item `index` with the lock released, then stores it under the lock.
  void produce_unlocked(std::size_t index, std::unique_lock<std::mutex>& lock) {
    lock.unlock();
    std::optional<T> item;
    std::exception_ptr error;
    try {
      item.emplace(produce_(index, stop_));
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    items_[index] = std::move(item);
    errors_[index] = error;
    changed_.notify_all();
  }

  void help() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      std::size_t index;
      if (next_claim_ >= items_.size()) return;
      if (claim(index)) {
        produce_unlocked(index, lock);
      } else {
        changed_.wait(lock);
      }
    }
  }

  const std::function<T(std::size_t, const std::atomic<bool>&)> produce_;
  const std::size_t lookahead_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::optional<T>> items_;
  std::vector<std::exception_ptr> errors_;
  std::size_t next_claim_ = 0, next_take_ = 0;
  std::atomic<bool> stop_{false};    // also polled by produce() without the lock
  std::vector<std::thread> helper_;  // none, or the one that started
};

}  // namespace primseg::detail
