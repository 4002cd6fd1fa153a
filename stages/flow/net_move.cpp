#include "stages/flow/net_move.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "engine/model/error.h"
#include "stages/flow/speed.h"

namespace mvflow {

NetNormalMove::NetNormalMove(int window) : window_(window) {
  MVFLOW_CHECK(window >= 1, "NetNormalMove: the window must be >= 1");
  ring_.resize(2 * static_cast<std::size_t>(window) + 1);
}

void NetNormalMove::reset() {
  next_ = 0;
  recorded_ = 0;
  last_tail_ = std::numeric_limits<double>::quiet_NaN();
  last_persistence_ = std::numeric_limits<double>::quiet_NaN();
}

double NetNormalMove::record(const TriMesh& mesh, const VertexFields& fields) {
  const std::size_t n = mesh.n_vertices();
  MVFLOW_CHECK(fields.size() == n, "NetNormalMove: fields are not sized for the mesh");
  MVFLOW_CHECK(recorded_ == 0 || ring_[(next_ + ring_.size() - 1) % ring_.size()].size() == n,
               "NetNormalMove: the vertex count changed without a reset");
  std::vector<Eigen::Vector3d>& now = ring_[next_];
  now.resize(n);
  for (std::size_t v = 0; v < n; ++v) now[v] = to_eigen(mesh.point(TriMesh::VertexHandle(static_cast<int>(v))));
  next_ = (next_ + 1) % ring_.size();
  ++recorded_;
  last_tail_ = std::numeric_limits<double>::quiet_NaN();
  last_persistence_ = std::numeric_limits<double>::quiet_NaN();
  const auto window = static_cast<std::size_t>(window_);
  if (recorded_ < window + 1) return std::numeric_limits<double>::quiet_NaN();

  const std::size_t slots = ring_.size();
  const std::vector<Eigen::Vector3d>& before = ring_[(next_ + slots - 1 - window) % slots];  // window iterations ago
  const bool two_windows = recorded_ >= slots;
  const std::vector<Eigen::Vector3d>& older = ring_[next_];  // 2·window ago, when two_windows
  std::vector<double> relative;
  relative.reserve(n);
  double product = 0.0, earlier_square = 0.0;  // Σ a·b, Σ b² (last_persistence)
  for (std::uint32_t v = 0; v < n; ++v) {
    if (!(fields.defined[v] & kSpeedDefined) || mesh.is_boundary(TriMesh::VertexHandle(static_cast<int>(v)))) continue;
    const double edge = fields.local_edge[v];
    if (!(edge > 0.0) || !std::isfinite(edge)) continue;
    const double last = (now[v] - before[v]).dot(fields.normal[v]) / edge;
    relative.push_back(std::abs(last));
    if (two_windows) {
      const double earlier = (before[v] - older[v]).dot(fields.normal[v]) / edge;
      product += last * earlier;
      earlier_square += earlier * earlier;
    }
  }
  if (relative.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (earlier_square > 0.0) last_persistence_ = product / earlier_square;
  const auto tail = relative.begin() +
                    static_cast<std::ptrdiff_t>(std::ceil(0.9 * static_cast<double>(relative.size()))) - 1;
  std::nth_element(relative.begin(), tail, relative.end());
  last_tail_ = *tail;
  return median_of(std::move(relative));
}

bool NetNormalMove::mean_of_last(std::size_t count, std::vector<Eigen::Vector3d>& mean) const {
  const std::size_t slots = ring_.size();
  MVFLOW_CHECK(count >= 1 && count <= slots, "NetNormalMove: mean_of_last needs 1 to 2·window + 1 positions");
  if (recorded_ < count) return false;
  const std::vector<Eigen::Vector3d>& newest = ring_[(next_ + slots - 1) % slots];
  mean = newest;
  for (std::size_t back = 2; back <= count; ++back) {
    const std::vector<Eigen::Vector3d>& earlier = ring_[(next_ + slots - back) % slots];
    for (std::size_t v = 0; v < mean.size(); ++v) mean[v] += earlier[v];
  }
  for (Eigen::Vector3d& p : mean) p /= static_cast<double>(count);
  return true;
}

}  // namespace mvflow
