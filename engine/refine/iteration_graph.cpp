#include "engine/refine/iteration_graph.h"

#include <oneapi/tbb/parallel_for.h>

namespace mvflow {

namespace flow = oneapi::tbb::flow;

IterationGraph::Node* IterationGraph::add(std::function<void()> body) {
  nodes_.push_back(std::make_unique<Node>(graph_, [body = std::move(body)](const flow::continue_msg&) { body(); }));
  return nodes_.back().get();
}

IterationGraph::IterationGraph(IterationData& data) {
  const IterationPhases schedule = iteration_phases(data.options, data.rim_masks != nullptr);
  const std::size_t n = data.blocks.size();
  start_ = add([&data] { data.refit(); });

  // Per block, the pipeline's kernels in a chain, each block independent of the others.
  Node* cfl = add([&data] { data.cfl(); });
  for (std::size_t b = 0; b < n; ++b) {
    Node* last = start_;
    for (BlockKernel kernel : schedule.pipeline) {
      Node* node = add([&data, b, kernel] { (data.*kernel)(b); });
      flow::make_edge(*last, *node);
      last = node;
    }
    flow::make_edge(*last, *cfl);  // the reduction waits for every block's partial
  }

  // One node per later phase: every block of the next phase may read any block's output of this
  // one (smoothing reads the neighbours' moved positions), so the phase's blocks run as a
  // parallel_for inside the node, and the edge to the next node is the barrier.
  Node* last = cfl;
  for (BlockKernel kernel : schedule.phases) {
    Node* node = add([&data, n, kernel] {
      oneapi::tbb::parallel_for(std::size_t{0}, n, [&data, kernel](std::size_t b) { (data.*kernel)(b); });
    });
    flow::make_edge(*last, *node);
    last = node;
  }
  flow::make_edge(*last, *add([&data] { data.measure_moves(); }));
}

void IterationGraph::run() {
  try {
    start_->try_put(flow::continue_msg());
    graph_.wait_for_all();
  } catch (...) {
    graph_.reset();  // clears the cancellation and the nodes' counters for the next run
    throw;
  }
  if (graph_.is_cancelled()) graph_.reset();
}

}  // namespace mvflow
