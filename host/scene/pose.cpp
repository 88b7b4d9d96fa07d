// pose_scene: one frame of an animated and/or turning scene (DESIGN section 7). Node transforms start at
// rest, the chosen clips' channels are sampled at the frame's time, world matrices follow the hierarchy,
// and only the instances that animations can move (SceneMotion::deformables) are recomputed. The
// turntable then turns everything about the pivot with p' = R p + (c - R c), which is the identity bit
// for bit when R is (frame 0, or any whole turn).
#include <algorithm>
#include <cmath>

#include "pmr/error.h"
#include "pmr/scene.h"
#include "scene/motion.h"

namespace pmr {

namespace {

bool clip_selected(int clip, int animation) { return animation == kAllAnimations || animation == clip; }

// Local matrices and morph weights of every node at time t.
void sample_nodes(const SceneMotion& m, const PoseRequest& r, std::vector<glm::dmat4>& local,
                  std::vector<std::vector<float>>& weights) {
  std::vector<MotionNode> nodes = m.nodes;
  std::vector<bool> touched(nodes.size(), false);
  for (size_t c = 0; c < m.clips.size(); ++c) {
    if (!clip_selected(int(c), r.animation)) continue;
    const MotionClip& clip = m.clips[c];
    for (const MotionChannel& ch : clip.channels) {
      const std::vector<float> v = sample(clip.samplers[size_t(ch.sampler)], r.time);
      MotionNode& n = nodes[size_t(ch.node)];
      switch (ch.path) {
        case ChannelPath::Translation:
          n.translation = glm::dvec3(v[0], v[1], v[2]);
          break;
        case ChannelPath::Scale:
          n.scale = glm::dvec3(v[0], v[1], v[2]);
          break;
        case ChannelPath::Rotation: {
          glm::dvec4 q(v[0], v[1], v[2], v[3]);
          const double len = glm::length(q);
          n.rotation = len > 0.0 && std::isfinite(len) ? q / len : glm::dvec4(0, 0, 0, 1);
          break;
        }
        case ChannelPath::Weights:
          n.weights = v;
          break;
      }
      touched[size_t(ch.node)] = true;
    }
  }
  local = rest_local_matrices(m);
  weights.resize(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (touched[i] && !nodes[i].has_matrix)
      local[i] = trs_matrix(nodes[i].translation, nodes[i].rotation, nodes[i].scale);
    weights[i] = std::move(nodes[i].weights);
  }
}

// Cameras and lights placed by their nodes' world matrices.
void place_cameras_and_lights(const SceneMotion& m, const std::vector<glm::dmat4>& world, Scene& out) {
  for (size_t c = 0; c < out.cameras.size() && c < m.camera_node.size(); ++c)
    if (m.camera_node[c] >= 0 && out.cameras[c].placed)
      out.cameras[c].world_from_camera = world[size_t(m.camera_node[c])];
  // Lights: the node's origin and -Z (a degenerate matrix keeps the rest direction), an area light's
  // plane and size.
  for (size_t l = 0; l < out.lights.size() && l < m.light_node.size(); ++l)
    place_light(out.lights[l], world[size_t(m.light_node[l])]);
}

// The world matrices of every node at the request's time, and their morph weights.
std::vector<glm::dmat4> posed_world(const SceneMotion& m, const PoseRequest& r,
                                    std::vector<std::vector<float>>& weights) {
  std::vector<glm::dmat4> local;
  sample_nodes(m, r, local, weights);
  return world_matrices(m, local);
}

void deform_instances(const Scene& rest, const SceneMotion& m, const PoseRequest& r, Scene& out) {
  std::vector<std::vector<float>> weights;
  const std::vector<glm::dmat4> world = posed_world(m, r, weights);
  std::vector<std::vector<glm::dmat4>> joints(m.skins.size());
  for (size_t s = 0; s < m.skins.size(); ++s) joints[s] = joint_matrices(m.skins[s], world);
  for (const Deformable& d : m.deformables) {
    const glm::dmat4& w = world[size_t(d.node)];
    const glm::dmat4* jm = d.skin >= 0 ? joints[size_t(d.skin)].data() : nullptr;
    glm::vec4* tangents = d.source->tan.empty() || out.tangents.empty() ? nullptr : &out.tangents[d.vertex_begin];
    deform(*d.source, weights[size_t(d.node)], jm, w, &out.positions[d.vertex_begin], &out.attributes[d.vertex_begin],
           nullptr, nullptr, tangents);
    const bool mirrored = d.skin < 0 && glm::determinant(glm::dmat3(w)) < 0.0;
    parallel_for(d.triangle_end - d.triangle_begin, 32768, [&](size_t b, size_t e) {
      for (size_t t = d.triangle_begin + b; t < d.triangle_begin + e; ++t) {
        PmrTriangle tri = rest.triangles[t];
        if (mirrored != d.rest_mirrored) std::swap(tri.v[1], tri.v[2]);
        const glm::vec3 n = face_normal(out.positions[tri.v[0]], out.positions[tri.v[1]], out.positions[tri.v[2]]);
        tri.face_normal[0] = n.x, tri.face_normal[1] = n.y, tri.face_normal[2] = n.z;
        out.triangles[t] = tri;
      }
    });
  }
  place_cameras_and_lights(m, world, out);
}

// Rotation about +Y by `deg` degrees, exact at multiples of 90 (so a quarter turn does not smear
// coordinates by sin(pi/2) rounding).
glm::dmat3 rotation_y(double deg) {
  double c, s;
  if (deg == 0.0) c = 1, s = 0;
  else if (deg == 90.0) c = 0, s = 1;
  else if (deg == 180.0) c = -1, s = 0;
  else if (deg == 270.0) c = 0, s = -1;
  else {
    const double a = deg * (3.14159265358979323846 / 180.0);
    c = std::cos(a), s = std::sin(a);
  }
  // Counter-clockwise seen from above (+Y): +X goes to -Z. Columns: images of X, Y, Z.
  return glm::dmat3(glm::dvec3(c, 0, -s), glm::dvec3(0, 1, 0), glm::dvec3(s, 0, c));
}

void turn_lights(const PoseRequest& r, std::vector<SceneLight>& lights) {
  const glm::dmat3 R = rotation_y(r.turntable_deg);
  const glm::dvec3 shift = r.pivot - R * r.pivot;
  for (SceneLight& l : lights) {
    l.position = R * l.position + shift;
    l.direction = R * l.direction;
    l.right = R * l.right, l.up = R * l.up;
  }
}

void turn(const PoseRequest& r, Scene& out) {
  const glm::dmat3 R = rotation_y(r.turntable_deg);
  const glm::dvec3 shift = r.pivot - R * r.pivot;
  for (size_t v = 0; v < out.positions.size(); ++v) {
    out.positions[v] = glm::vec3(R * glm::dvec3(out.positions[v]) + shift);
    float* n = out.attributes[v].normal;
    const glm::dvec3 rn = R * glm::dvec3(n[0], n[1], n[2]);
    for (int c = 0; c < 3; ++c) n[c] = float(rn[c]);
  }
  for (PmrTriangle& t : out.triangles) {
    const glm::dvec3 rn = R * glm::dvec3(t.face_normal[0], t.face_normal[1], t.face_normal[2]);
    for (int c = 0; c < 3; ++c) t.face_normal[c] = float(rn[c]);
  }
  // A rotation keeps handedness: w stays.
  for (glm::vec4& t : out.tangents) t = glm::vec4(glm::vec3(R * glm::dvec3(t)), t.w);
  turn_lights(r, out.lights);
}

bool animates(const Scene& rest, const PoseRequest& r) {
  if (!rest.motion || r.animation == kNoAnimation) return false;
  for (size_t c = 0; c < rest.motion->clips.size(); ++c)
    if (clip_selected(int(c), r.animation) && !rest.motion->clips[c].channels.empty()) return true;
  return false;
}

void check_request(const Scene& rest, const PoseRequest& r) {
  if (r.animation != kNoAnimation && r.animation != kAllAnimations &&
      (r.animation < 0 || size_t(r.animation) >= rest.animations.size()))
    throw Error("pose_scene: no animation " + std::to_string(r.animation));
}

}  // namespace

double turntable_angle(long frame, double degrees, long frames) {
  if (frames <= 0) throw Error("turntable_angle: FRAMES must be positive");
  // f * DEG / FRAMES reduced modulo 360; fmod is exact, so whole turns give exactly 0.
  const double a = std::fmod(double(frame) * degrees, 360.0 * double(frames)) / double(frames);
  return a < 0.0 ? a + 360.0 : a;
}

bool pose_moves(const Scene& rest, const PoseRequest& r) { return r.turntable || animates(rest, r); }

void pose_cameras_and_lights(const Scene& rest, const PoseRequest& r, Scene& out) {
  check_request(rest, r);
  out.cameras = rest.cameras;
  out.lights = rest.lights;
  if (animates(rest, r)) {
    std::vector<std::vector<float>> weights;
    place_cameras_and_lights(*rest.motion, posed_world(*rest.motion, r, weights), out);
  }
  if (r.turntable) turn_lights(r, out.lights);
}

uint64_t pose_work(const Scene& rest, int animation) {
  uint64_t work = rest.positions.size();
  if (!rest.motion || animation == kNoAnimation) return work;
  const SceneMotion& m = *rest.motion;
  // Sums of sizes the loader has already allocated: none of them can overflow 64 bits.
  work += kPoseNodeUnits * m.nodes.size();
  for (const MotionNode& n : m.nodes) work += n.weights.size();
  for (const MotionSkin& s : m.skins) work += kPoseJointUnits * s.joints.size();
  for (size_t c = 0; c < m.clips.size(); ++c)
    if (clip_selected(int(c), animation))
      for (const MotionChannel& ch : m.clips[c].channels) work += m.clips[c].samplers[size_t(ch.sampler)].width;
  for (const Deformable& d : m.deformables)
    work += d.source->vertices * (1 + d.source->target_pos.size()) + (d.triangle_end - d.triangle_begin);
  return work;
}

bool pose_scene(const Scene& rest, const PoseRequest& r, Scene& out) {
  check_request(rest, r);
  const bool animated = animates(rest, r);
  // Sizes differ on first use; afterwards only what a pose can change needs resetting.
  if (out.positions.size() != rest.positions.size() || out.triangles.size() != rest.triangles.size() ||
      out.tangents.size() != rest.tangents.size() || r.turntable) {
    out.positions = rest.positions;
    out.attributes = rest.attributes;
    out.triangles = rest.triangles;
    out.tangents = rest.tangents;
  }
  out.cameras = rest.cameras;
  out.lights = rest.lights;
  if (animated) {
    deform_instances(rest, *rest.motion, r, out);
  } else if (rest.motion) {  // undo an earlier animated pose of the moving instances
    for (const Deformable& d : rest.motion->deformables) {
      const size_t n = d.source->vertices;
      std::copy_n(&rest.positions[d.vertex_begin], n, &out.positions[d.vertex_begin]);
      std::copy_n(&rest.attributes[d.vertex_begin], n, &out.attributes[d.vertex_begin]);
      if (!rest.tangents.empty()) std::copy_n(&rest.tangents[d.vertex_begin], n, &out.tangents[d.vertex_begin]);
      std::copy(&rest.triangles[d.triangle_begin], &rest.triangles[0] + d.triangle_end,
                &out.triangles[d.triangle_begin]);
    }
  }
  if (r.turntable) turn(r, out);
  return r.turntable || (animated && !rest.motion->deformables.empty());
}

}  // namespace pmr
