// The loader's half of animation: the node hierarchy, clips and skins of a glTF model read into a
// SceneMotion (motion.h), and which nodes any clip can move. The structure was checked on the JSON
// (gltf_schema.cpp) and the key times by validate_model; what is checked here is what only the decoded
// data shows (sampler sizes, inverse bind matrix counts).
#include <cmath>

#include "scene/gltf_internal.h"

namespace pmr::gltf {

namespace {

ChannelPath channel_path(const std::string& path) {
  if (path == "translation") return ChannelPath::Translation;
  if (path == "rotation") return ChannelPath::Rotation;
  if (path == "scale") return ChannelPath::Scale;
  return ChannelPath::Weights;  // the schema check admits nothing else
}

// Morph targets of the node's mesh (all primitives of a mesh have the same number: check_morphs).
size_t node_targets(const tinygltf::Model& m, int node) {
  const int mesh = m.nodes[size_t(node)].mesh;
  if (mesh < 0 || m.meshes[size_t(mesh)].primitives.empty()) return 0;
  return m.meshes[size_t(mesh)].primitives[0].targets.size();
}

MotionClip read_clip(const tinygltf::Model& m, size_t a, const std::string& file) {
  const tinygltf::Animation& anim = m.animations[a];
  MotionClip clip;
  clip.name = anim.name;
  // Which width each sampler's values have comes from the channels that use it.
  std::vector<int> width(anim.samplers.size(), 0);
  std::vector<bool> rotation(anim.samplers.size(), false);
  for (size_t c = 0; c < anim.channels.size(); ++c) {
    const tinygltf::AnimationChannel& ch = anim.channels[c];
    if (ch.target_node < 0) continue;  // (schema: an extension targets something else; nothing to animate)
    MotionChannel mc;
    mc.node = ch.target_node;
    mc.path = channel_path(ch.target_path);
    mc.sampler = ch.sampler;
    const int w = mc.path == ChannelPath::Rotation  ? 4
                  : mc.path == ChannelPath::Weights ? int(node_targets(m, mc.node))
                                                    : 3;
    if (width[size_t(ch.sampler)] != 0 && width[size_t(ch.sampler)] != w)
      fail(file, "animation " + std::to_string(a) + " sampler " + std::to_string(ch.sampler) +
                     " drives channels of different kinds");
    width[size_t(ch.sampler)] = w;
    rotation[size_t(ch.sampler)] = mc.path == ChannelPath::Rotation;
    clip.channels.push_back(mc);
  }
  bool any = false;
  for (size_t s = 0; s < anim.samplers.size(); ++s) {
    const tinygltf::AnimationSampler& smp = anim.samplers[s];
    const std::string where = "animation " + std::to_string(a) + " sampler " + std::to_string(s);
    AnimationSampler out;
    out.interpolation = parse_interpolation(smp.interpolation.empty() ? "LINEAR" : smp.interpolation);
    out.times = read_attribute(m, smp.input, Semantic::KeyTimes, "input of " + where, file).values;
    out.width = width[s];
    out.rotation = rotation[s];
    if (out.width > 0) {
      out.values = read_attribute(m, smp.output, Semantic::AnimationOutput, "output of " + where, file).values;
      const size_t per_key = size_t(out.width) * (out.interpolation == Interpolation::CubicSpline ? 3 : 1);
      if (out.values.size() != out.times.size() * per_key)
        fail(file, where + " has " + std::to_string(out.values.size()) + " output values for " +
                       std::to_string(out.times.size()) + " keys (" + std::to_string(per_key) + " per key expected)");
    }
    if (!out.times.empty()) {
      clip.start = any ? std::min(clip.start, double(out.times.front())) : out.times.front();
      clip.end = any ? std::max(clip.end, double(out.times.back())) : out.times.back();
      any = true;
    }
    clip.samplers.push_back(std::move(out));
  }
  return clip;
}

MotionSkin read_skin(const tinygltf::Model& m, size_t s, const std::string& file) {
  const tinygltf::Skin& skin = m.skins[s];
  MotionSkin out;
  out.joints = skin.joints;
  out.inverse_bind.assign(skin.joints.size(), glm::dmat4(1.0));
  if (skin.inverseBindMatrices >= 0) {
    const std::string what = "inverseBindMatrices of skin " + std::to_string(s);
    const AttributeData d = read_attribute(m, skin.inverseBindMatrices, Semantic::InverseBind, what, file);
    if (d.count < skin.joints.size())
      fail(file, "accessor " + std::to_string(skin.inverseBindMatrices) + " (" + what + ") has " +
                     std::to_string(d.count) + " matrices for " + std::to_string(skin.joints.size()) + " joints");
    for (size_t j = 0; j < skin.joints.size(); ++j)
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
          const float v = d.values[16 * j + size_t(4 * c + r)];
          if (!std::isfinite(v)) fail(file, what + ": matrix " + std::to_string(j) + " is not finite");
          out.inverse_bind[j][c][r] = v;
        }
  }
  return out;
}

}  // namespace

std::shared_ptr<SceneMotion> read_motion(const tinygltf::Model& m, const std::vector<int>& parent,
                                         const std::string& file) {
  auto motion = std::make_shared<SceneMotion>();
  const size_t n = m.nodes.size();
  motion->nodes.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const tinygltf::Node& node = m.nodes[i];
    motion->nodes[i] = node_transform(node, int(i), file);
    motion->nodes[i].parent = parent[i];
    const size_t targets = node_targets(m, int(i));
    if (targets > 0) {
      const std::vector<double>& w = !node.weights.empty() ? node.weights : m.meshes[size_t(node.mesh)].weights;
      if (!w.empty() && w.size() != targets)
        fail(file, "node " + std::to_string(i) + " has " + std::to_string(w.size()) + " morph weights for " +
                       std::to_string(targets) + " morph targets");
      motion->nodes[i].weights.assign(targets, 0.0f);
      for (size_t k = 0; k < w.size(); ++k) {
        if (!std::isfinite(w[k])) fail(file, "node " + std::to_string(i) + " has a non-finite morph weight");
        motion->nodes[i].weights[k] = float(w[k]);
      }
    }
  }
  // Parents before children: a pre-order walk from every root (the hierarchy is a checked forest).
  std::vector<std::vector<int>> children(n);
  for (size_t i = 0; i < n; ++i)
    if (parent[i] >= 0) children[size_t(parent[i])].push_back(int(i));
  std::vector<int> stack;
  for (size_t i = n; i-- > 0;)
    if (parent[i] < 0) stack.push_back(int(i));
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    motion->order.push_back(i);
    for (auto c = children[size_t(i)].rbegin(); c != children[size_t(i)].rend(); ++c) stack.push_back(*c);
  }
  for (size_t a = 0; a < m.animations.size(); ++a) motion->clips.push_back(read_clip(m, a, file));
  for (size_t s = 0; s < m.skins.size(); ++s) motion->skins.push_back(read_skin(m, s, file));
  motion->camera_node.assign(m.cameras.size(), -1);
  return motion;
}

std::vector<bool> moving_nodes(const SceneMotion& motion) {
  std::vector<bool> moves(motion.nodes.size(), false);
  for (const MotionClip& clip : motion.clips)
    for (const MotionChannel& ch : clip.channels)
      if (ch.path != ChannelPath::Weights) moves[size_t(ch.node)] = true;
  for (int i : motion.order) {  // a node moves with its parent
    const int p = motion.nodes[size_t(i)].parent;
    if (p >= 0 && moves[size_t(p)]) moves[size_t(i)] = true;
  }
  return moves;
}

}  // namespace pmr::gltf
