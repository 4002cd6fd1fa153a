#include "engine/refine/iteration_graph.h"

namespace mvflow {

namespace flow = oneapi::tbb::flow;

IterationGraph::Node* IterationGraph::add(std::function<void()> body) {
  nodes_.push_back(std::make_unique<Node>(graph_, [body = std::move(body)](const flow::continue_msg&) { body(); }));
  return nodes_.back().get();
}

IterationGraph::Node* IterationGraph::barrier() {
  return add([] {});
}

IterationGraph::IterationGraph(IterationData& data) : n_blocks_(data.blocks.size()) {
  const std::size_t n = n_blocks_;
  start_ = add([&data] { data.refit(); });

  // Per block: geometry → visibility → photo/gradient/speed, pipelined independently.
  Node* cfl = add([&data] { data.cfl(); });
  for (std::size_t b = 0; b < n; ++b) {
    Node* geometry = add([&data, b] { data.geometry(b); });
    Node* visibility = add([&data, b] { data.visibility(b); });
    Node* photo = add([&data, b] { data.photo_speed(b); });
    flow::make_edge(*start_, *geometry);
    flow::make_edge(*geometry, *visibility);
    flow::make_edge(*visibility, *photo);
    flow::make_edge(*photo, *cfl);  // the reduction waits for every block's partial
  }

  // A phase of per-block nodes between two barriers: every block of the next phase may read
  // any block's output of this one (smoothing reads the neighbours' moved positions).
  auto phase = [&](Node* before, auto kernel) {
    Node* after = barrier();
    for (std::size_t b = 0; b < n; ++b) {
      Node* node = add([&data, b, kernel] { (data.*kernel)(b); });
      flow::make_edge(*before, *node);
      flow::make_edge(*node, *after);
    }
    return after;
  };
  Node* last = phase(cfl, &IterationData::move);
  for (int step = 0; step < data.options.smoothing.steps; ++step) {
    last = phase(last, &IterationData::smooth);
    last = phase(last, &IterationData::commit);
    if (data.options.smoothing.taubin_pass_band > 0.0) {
      last = phase(last, &IterationData::inflate);
      last = phase(last, &IterationData::commit);
    }
  }
  for (int step = 0; step < data.options.regularization.steps; ++step) {
    last = phase(last, &IterationData::regularize);
    last = phase(last, &IterationData::commit);
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
