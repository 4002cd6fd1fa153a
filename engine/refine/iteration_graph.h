#pragma once
// One deformation iteration as a oneTBB flow graph (SPEC §6): a dependence graph of
// continue_nodes over the shared IterationData (the shape of oneTBB's cholesky example), built
// from iteration_phases (engine/refine/iteration.h), the schedule the sequential path walks too.
//
//   refit ─┬─ geometry₀ → visibility₀ → photo₀ ─┐
//          ├─ geometry₁ → visibility₁ → photo₁ ─┤
//          └─ …                                  ┴─ cfl ─ move ─ smooth ─ commit ─ … ─ regularize ─ commit ─ measure
//
// Before the CFL reduction, nodes per block where they buy pipelining: a block's photo node
// starts as soon as its own geometry and visibility are done, and the only global barrier is the
// refit. After it, every phase reads neighbours across blocks, so each phase is one node whose
// body is a parallel_for over the blocks (the graph is the coarse level, oneTBB's nested
// parallelism). Built once per topology (the block count and ranges are baked into the nodes);
// run many times.

#include <deque>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include <oneapi/tbb/flow_graph.h>

#include "engine/refine/iteration.h"

namespace mvflow {

class IterationGraph {
 public:
  //! Builds the nodes for data.blocks. The graph attaches to the task arena that is current
  //! where it is constructed, so construct it inside the engine's arena.
  explicit IterationGraph(IterationData& data);
  IterationGraph(const IterationGraph&) = delete;
  IterationGraph& operator=(const IterationGraph&) = delete;

  //! Runs one iteration and waits for it. Rethrows the first exception a node threw (after
  //! cancelling the rest); the graph is reset and can run again either way. Once the cancel flag
  //! is set the rest of the graph drains: every kernel checks the flag and returns at once (the
  //! whole graph with empty bodies takes 0.06 ms at 10k vertices, perf/README.md), so the flag
  //! needs no cancellation of the graph's task_group_context.
  void run();

 private:
  using Node = oneapi::tbb::flow::continue_node<oneapi::tbb::flow::continue_msg>;
  Node* add(std::function<void()> body);
  //! flow::make_edge(from, to), recorded for ThreadSanitizer (engine/model/parallel.h).
  void edge(Node& from, Node& to);

  oneapi::tbb::flow::graph graph_;  // declared before the nodes: it must outlive them
  std::vector<std::unique_ptr<Node>> nodes_;
  // Under TSan only: each node's body, whose address stands for the node's completion, and its
  // predecessors' completions, which happen before it (the edges run inside libtbb.so, which
  // TSan does not see; engine/model/parallel.h says more).
  std::deque<std::function<void()>> tsan_bodies_;
  std::vector<std::vector<const void*>> predecessors_;
  std::unordered_map<const Node*, std::size_t> index_of_;
  Node* start_ = nullptr;
};

}  // namespace mvflow
