#include "engine/refine/iteration_graph.h"

#include "engine/model/parallel.h"

namespace mvflow {

namespace flow = oneapi::tbb::flow;

IterationGraph::Node* IterationGraph::add(std::function<void()> body) {
#ifdef MVFLOW_TSAN
  const std::size_t index = nodes_.size();
  predecessors_.emplace_back();
  const std::function<void()>& wrapped = tsan_bodies_.emplace_back([this, index, body = std::move(body)] {
    parallel::acquire(&graph_);  // run()'s caller, after the graph was built
    for (const void* predecessor : predecessors_[index]) parallel::acquire(predecessor);
    body();
  });
  nodes_.push_back(std::make_unique<Node>(
      graph_, [handed = parallel::HandedOver<std::function<void()>>(wrapped, &wrapped)](const flow::continue_msg&) {
        handed();
      }));
  index_of_.emplace(nodes_.back().get(), index);
#else
  nodes_.push_back(std::make_unique<Node>(graph_, [body = std::move(body)](const flow::continue_msg&) { body(); }));
#endif
  return nodes_.back().get();
}

void IterationGraph::edge(Node& from, Node& to) {
  flow::make_edge(from, to);
#ifdef MVFLOW_TSAN
  predecessors_[index_of_.at(&to)].push_back(&tsan_bodies_[index_of_.at(&from)]);
#endif
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
      edge(*last, *node);
      last = node;
    }
    edge(*last, *cfl);  // the reduction waits for every block's partial
  }

  // One node per later phase: every block of the next phase may read any block's output of this
  // one (smoothing reads the neighbours' moved positions), so the phase's blocks run as a
  // parallel_for inside the node, and the edge to the next node is the barrier.
  Node* last = cfl;
  for (BlockKernel kernel : schedule.phases) {
    Node* node = add([&data, n, kernel] {
      parallel::parallel_for(std::size_t{0}, n, [&data, kernel](std::size_t b) { (data.*kernel)(b); });
    });
    edge(*last, *node);
    last = node;
  }
  edge(*last, *add([&data] { data.measure_moves(); }));
}

void IterationGraph::run() {
  // Under TSan: the caller's work happens before the first node, every node's before the return.
  parallel::release(&graph_);
  const auto joined = [this] {
#ifdef MVFLOW_TSAN
    for (const auto& body : tsan_bodies_) parallel::acquire(&body);
#endif
  };
  try {
    start_->try_put(flow::continue_msg());
    graph_.wait_for_all();
  } catch (...) {
    joined();
    graph_.reset();  // clears the cancellation and the nodes' counters for the next run
    throw;
  }
  joined();
  if (graph_.is_cancelled()) graph_.reset();
}

}  // namespace mvflow
