#pragma once
// A benchmark's seam (bench/evaluation_floor.cpp): the outcomes of a build's candidate
// evaluations, recorded in the order the build makes them, then replayed by a second build of the
// same mesh and options instead of evaluating. The replaying build does everything else a build
// does (the dual graph, the first degrees, the relinking, the queue, each merge's own fit and
// statistics, the tree's records, the prefetches), so its time is the floor of the exact merge
// order: what a build would take if candidate evaluations cost nothing.
//
// One global tape, for one builder on one thread: HierarchyBuilder refuses a tape that is not
// Off with more than one thread or with regions, whose evaluations run in no fixed order. Off,
// the builder reads it once, when it is constructed.

#include <cstddef>
#include <vector>

#include "primseg/primitive.hpp"

namespace primseg::detail {

/// What a candidate's evaluation gives the merge loop.
struct EvaluationOutcome {
  double cost = 0;
  double cost_bound = 0;  // the edge's lazy bound as the evaluation left it
  PrimitiveType type = PrimitiveType::Plane;
};

struct EvaluationTape {
  enum class Mode { Off, Record, Replay };
  Mode mode = Mode::Off;
  std::vector<EvaluationOutcome> outcomes;
  std::size_t next = 0;  // Replay: the next outcome to hand out
};

inline EvaluationTape evaluation_tape;

}  // namespace primseg::detail
