// /tf and /tf_static as a tree (see tf_tree.hpp).
#include "ros2/tf_tree.hpp"

#include <algorithm>
#include <deque>
#include <set>

namespace umbmark::io::rosbag2 {

Pose2 PlanarPose(const PoseMsg& p) { return {p.x, p.y, p.Yaw()}; }

double TfEdge::RateHz() const {
  if (count < 2 || last_ns <= first_ns) return 0.0;
  return static_cast<double>(count - 1) / (static_cast<double>(last_ns - first_ns) * 1e-9);
}

void TfTree::Add(const PoseMsg& t, bool is_static) {
  std::string key;
  key.reserve(t.header.frame_id.size() + t.child_frame_id.size() + 3);
  key.append(t.header.frame_id).append("\n").append(t.child_frame_id).append(is_static ? "\ns" : "\nd");
  auto it = index_.find(key);
  if (it == index_.end()) {
    if (edges_.size() >= kMaxEdges) {
      ++dropped_;
      return;
    }
    it = index_.emplace(std::move(key), edges_.size()).first;
    TfEdge e;
    e.parent = std::string(t.header.frame_id);
    e.child = std::string(t.child_frame_id);
    e.is_static = is_static;
    e.first_ns = e.last_ns = t.header.stamp_ns;
    edges_.push_back(std::move(e));
  }
  TfEdge& e = edges_[it->second];
  ++e.count;
  e.first_ns = std::min(e.first_ns, t.header.stamp_ns);
  e.last_ns = std::max(e.last_ns, t.header.stamp_ns);
  e.last = PlanarPose(t);
}

const TfEdge* TfTree::ParentEdge(std::string_view child) const {
  const TfEdge* found = nullptr;
  for (const auto& e : edges_) {
    if (e.child != child) continue;
    if (!e.is_static) return &e;
    if (!found) found = &e;
  }
  return found;
}

std::vector<std::string> TfTree::Chain(std::string_view frame) const {
  std::vector<std::string> chain{std::string(frame)};
  std::set<std::string, std::less<>> seen{std::string(frame)};
  while (const TfEdge* e = ParentEdge(chain.back())) {
    if (!seen.insert(e->parent).second) break;
    chain.push_back(e->parent);
  }
  return chain;
}

std::optional<std::string> TfTree::OdometryFrameAbove(std::string_view frame,
                                                      const std::vector<std::string>& odom_frames) const {
  const auto chain = Chain(frame);
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const std::string& f = chain[i];
    const bool listed = std::find(odom_frames.begin(), odom_frames.end(), f) != odom_frames.end();
    if (listed || f.find("odom") != std::string::npos) return f;
  }
  return std::nullopt;
}

// Breadth-first over the static edges, carrying X_T_frame for every frame X
// reached, until a frame with a moving parent edge.
std::optional<std::pair<std::string, Pose2>> TfTree::StaticAnchor(std::string_view frame) const {
  auto moving = [&](std::string_view f) {
    return std::any_of(edges_.begin(), edges_.end(), [&](const TfEdge& e) { return !e.is_static && e.child == f; });
  };
  std::map<std::string, Pose2, std::less<>> reached{{std::string(frame), Pose2{}}};
  std::deque<std::string> pending{std::string(frame)};
  while (!pending.empty()) {
    const std::string x = pending.front();
    pending.pop_front();
    const Pose2 x_T_frame = reached.at(x);
    if (x != frame && moving(x)) return std::make_pair(x, x_T_frame);
    for (const auto& e : edges_) {
      if (!e.is_static) continue;
      if (e.child == x && !reached.count(e.parent)) {
        reached[e.parent] = Compose(e.last, x_T_frame);
        pending.push_back(e.parent);
      } else if (e.parent == x && !reached.count(e.child)) {
        reached[e.child] = Compose(Inverse(e.last), x_T_frame);
        pending.push_back(e.child);
      }
    }
  }
  return std::nullopt;
}

}  // namespace umbmark::io::rosbag2
