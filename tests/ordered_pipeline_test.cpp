#include "ordered_pipeline.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

namespace primseg::detail {
namespace {

using namespace std::chrono_literals;

// Polls `condition` for up to ten seconds (a loaded machine may not schedule the helper at once).
template <typename Condition>
bool eventually(const Condition& condition) {
  for (int i = 0; i < 1000; ++i) {
    if (condition()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return condition();
}

TEST(OrderedPipeline, TakesEveryItemInOrderWithOrWithoutTheHelper) {
  for (const bool helper : {false, true})
    for (std::size_t lookahead = 1; lookahead <= 3; ++lookahead)
      for (std::size_t count = 0; count <= 6; ++count) {
        OrderedPipeline<std::string> pipeline(
            count, lookahead, helper, [](std::size_t i, const std::atomic<bool>&) {
              return std::string(i + 1, 'x');  // unequal sizes: items are moved out whole
            });
        for (std::size_t i = 0; i < count; ++i)
          EXPECT_EQ(pipeline.take(), std::string(i + 1, 'x'))
              << "helper " << helper << ", lookahead " << lookahead << ", count " << count;
        EXPECT_THROW(pipeline.take(), std::out_of_range);
      }
}

TEST(OrderedPipeline, WithoutTheHelperTheCallerProducesEachItemWhenTaken) {
  std::set<std::thread::id> producers;
  std::size_t produced = 0;
  OrderedPipeline<int> pipeline(4, 3, false, [&](std::size_t i, const std::atomic<bool>&) {
    producers.insert(std::this_thread::get_id());
    ++produced;
    return static_cast<int>(i);
  });
  EXPECT_EQ(produced, 0u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(pipeline.take(), i);
    EXPECT_EQ(produced, static_cast<std::size_t>(i) + 1);  // nothing made ahead
  }
  EXPECT_EQ(producers, std::set{std::this_thread::get_id()});
}

TEST(OrderedPipeline, TheHelperMakesItemsAheadUpToTheLookahead) {
  std::atomic<int> produced{0};
  std::atomic<bool> other_thread{false};
  const std::thread::id caller = std::this_thread::get_id();
  OrderedPipeline<int> pipeline(10, 3, true, [&](std::size_t i, const std::atomic<bool>&) {
    if (std::this_thread::get_id() != caller) other_thread = true;
    ++produced;
    return static_cast<int>(i);
  });
  // Before any take(): items 0, 1 and 2, and no more.
  EXPECT_TRUE(eventually([&] { return produced == 3; }));
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(produced, 3);
  EXPECT_TRUE(other_thread);
  EXPECT_EQ(pipeline.take(), 0);
  EXPECT_TRUE(eventually([&] { return produced == 4; }));  // room for item 3
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(produced, 4);
  for (int i = 1; i < 10; ++i) EXPECT_EQ(pipeline.take(), i);
  EXPECT_EQ(produced, 10);
}

TEST(OrderedPipeline, AnItemsErrorIsThrownWhenThatItemIsTaken) {
  for (const bool helper : {false, true}) {
    OrderedPipeline<int> pipeline(5, 2, helper, [](std::size_t i, const std::atomic<bool>&) {
      if (i == 2) throw std::runtime_error("item 2");
      return static_cast<int>(i);
    });
    EXPECT_EQ(pipeline.take(), 0);
    EXPECT_EQ(pipeline.take(), 1);
    try {
      pipeline.take();
      ADD_FAILURE() << "item 2 did not throw";
    } catch (const std::runtime_error& error) {
      EXPECT_STREQ(error.what(), "item 2");
    }
    EXPECT_EQ(pipeline.take(), 3);  // the others are unaffected
    EXPECT_EQ(pipeline.take(), 4);
  }
}

TEST(OrderedPipeline, DestroyingItStopsTheHelperWithinItsItem) {
  std::atomic<int> started{0};
  const auto begin = std::chrono::steady_clock::now();
  {
    OrderedPipeline<int> pipeline(1000, 2, true, [&](std::size_t i, const std::atomic<bool>& stop) {
      ++started;
      // An item that would take a minute unless stopped.
      for (int step = 0; step < 60000 && !stop; ++step) std::this_thread::sleep_for(1ms);
      if (stop) throw std::runtime_error("stopped");
      return static_cast<int>(i);
    });
    EXPECT_TRUE(eventually([&] { return started >= 1; }));
  }
  EXPECT_LT(std::chrono::steady_clock::now() - begin, 30s);
  EXPECT_LE(started, 2);  // no item started once stopped
}

}  // namespace
}  // namespace primseg::detail
