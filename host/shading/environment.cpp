// Environment lighting: choosing and making the environment, and sampling its tables on the host as the
// kernels do (environment.h). The prefilter itself is environment_prefilter.cpp.
#include "shading/environment.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "pmr/error.h"
#include "pmr/printable.h"
#include "shading/environment_lights.h"
#include "shading/environment_prefilter.h"
#include "shading/sheen.h"
#include "shading/studio_environment.h"

namespace pmr {
namespace {

constexpr double kPi = 3.14159265358979323846;

inline glm::dvec3 unit_or_up(const glm::dvec3& d) {
  const double len = glm::length(d);
  return len > 0.0 && std::isfinite(len) ? d / len : glm::dvec3(0.0, 1.0, 0.0);
}

}  // namespace

namespace {

// Bilinear lookup of an N x N table of C-float nodes, node (i, j) at C (j N + i), at node coordinates
// (x, y) in [0, N - 1]: the split-sum and sheen albedo tables, as the kernels read them.
template <int C>
glm::vec<C, double> node_bilinear(const std::vector<float>& t, int N, double x, double y) {
  const int i0 = std::min(int(x), N - 2), j0 = std::min(int(y), N - 2);
  const double fx = x - i0, fy = y - j0;
  auto at = [&](int i, int j) {
    glm::vec<C, double> v;
    for (int c = 0; c < C; ++c) v[c] = t[size_t(C * (j * N + i) + c)];
    return v;
  };
  return (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i0 + 1, j0)) +
         fy * ((1 - fx) * at(i0, j0 + 1) + fx * at(i0 + 1, j0 + 1));
}

// sqrt(n.v) in node units (non-finite: 0), the tables' first coordinate.
double cosine_node(double n_dot_v, int N) {
  return std::sqrt(std::clamp(std::isfinite(n_dot_v) ? n_dot_v : 0.0, 0.0, 1.0)) * (N - 1);
}

}  // namespace

glm::dvec2 split_sum(double n_dot_v, double r) {
  const int N = kEnvSplitSumSize;
  const double y = std::clamp(std::isfinite(r) ? r : 1.0, 0.0, 1.0) * (N - 1);
  return node_bilinear<2>(split_sum_table(), N, cosine_node(n_dot_v, N), y);
}

const std::vector<float>& sheen_albedo_table() {
  // computed at build time (pmr_brdf_tables_gen): a few seconds of CPU
  static const std::vector<float> table(kSheenAlbedoTable, kSheenAlbedoTable + kSheenAlbedoSize * kSheenAlbedoSize);
  return table;
}

double sheen_albedo(double nv, double r) {
  const int N = kSheenAlbedoSize;
  const double y = (sheen_roughness(r) - kSheenMinRoughness) / (1.0 - kSheenMinRoughness) * (N - 1);
  return node_bilinear<1>(sheen_albedo_table(), N, cosine_node(nv, N), y).x;
}

Environment Environment::uniform(double radiance) {
  if (!std::isfinite(radiance) || radiance < 0.0)
    throw Error("environment: the uniform radiance must be finite and >= 0");
  Environment e;
  e.tables_ = uniform_environment_tables(float(radiance));
  return e;
}

Environment Environment::from_image(const EnvironmentImage& image, const std::string& name) {
  const auto start = std::chrono::steady_clock::now();
  EnvironmentImage checked = image;
  check_environment_image(checked, name);
  Environment e;
  e.tables_ = prefilter_environment(checked);
  e.prefilter_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

// The studio's tables as the build prefiltered them (generated/studio_tables.S: the EnvTablesHeader's
// bytes, then the floats; tools/studio_gen.cpp).
extern "C" const unsigned char pmr_studio_tables_begin[], pmr_studio_tables_end[];

Environment Environment::studio() {
  const unsigned char* at = pmr_studio_tables_begin;
  const size_t bytes = size_t(pmr_studio_tables_end - at), header = sizeof(EnvTablesHeader);
  if (bytes < header || (bytes - header) % sizeof(float) != 0)
    throw InternalError("the built-in studio environment's tables are damaged");
  Environment e;
  std::memcpy(&e.tables_.header, at, header);
  e.tables_.data.resize((bytes - header) / sizeof(float));
  std::memcpy(e.tables_.data.data(), at + header, bytes - header);
  return e;
}

Environment Environment::studio_walls() {
  Environment e = from_image(studio_walls_image(), "studio walls");
  e.distant_ = studio_box_lights();
  return e;
}

Environment Environment::with_lights_taken_out(EnvironmentImage image, const std::string& name) {
  check_environment_image(image, name);
  std::vector<SceneLight> lights = take_out_bright_regions(image);
  Environment e = from_image(image, name);
  e.distant_ = std::move(lights);
  return e;
}

std::vector<SceneLight> Environment::distant_lights() const {
  // an environment turned off (intensity 0, e.g. Blender's black world) brings no lights: nothing to
  // shade, and no shadow maps to render
  if (tables_.header.intensity == 0.0f) return {};
  const double c = tables_.header.rotation_cos, s = tables_.header.rotation_sin;
  // the map turned by +angle shows at d what the image holds at d turned by -angle (level_sample): a
  // box at b is seen at b turned by +angle
  const auto turn = [c, s](const glm::dvec3& b) { return glm::dvec3(c * b.x + s * b.z, b.y, c * b.z - s * b.x); };
  std::vector<SceneLight> out = distant_;
  for (SceneLight& l : out) {
    l.position = turn(l.position), l.direction = turn(l.direction), l.right = turn(l.right), l.up = turn(l.up);
    l.intensity = float(double(l.intensity) * double(tables_.header.intensity));
  }
  return out;
}

EnvironmentSource EnvironmentSource::parse(const std::string& text) {
  if (text.empty()) throw Error("invalid --environment '': expected studio, uniform or a .hdr or .exr file");
  if (text == "studio") return {Kind::Studio, ""};
  if (text == "uniform") return {Kind::Uniform, ""};
  return {Kind::File, text};
}

std::string EnvironmentSource::name() const {
  return kind == Kind::Studio ? "studio" : kind == Kind::Uniform ? "uniform" : file;
}

namespace {

void check_rotation_and_intensity(const EnvironmentOptions& o) {
  if (!std::isfinite(o.intensity) || o.intensity < 0.0)
    throw Error("environment intensity must be a finite number >= 0");
  if (!std::isfinite(o.rotation_deg)) throw Error("environment rotation must be a finite number of degrees");
}

}  // namespace

Environment Environment::make(const EnvironmentOptions& o) {
  check_rotation_and_intensity(o);
  const EnvironmentSource& s = o.source;
  Environment e = s.kind == EnvironmentSource::Kind::Studio    ? (o.take_out_lights ? studio_walls() : studio())
                  : s.kind == EnvironmentSource::Kind::Uniform ? uniform(o.uniform_radiance)
                  : o.take_out_lights ? with_lights_taken_out(load_environment_image(s.file), s.file)
                                      : from_image(load_environment_image(s.file), s.file);
  e.set_rotation(o.rotation_deg);
  e.set_intensity(o.intensity);
  return e;
}

std::shared_ptr<const Environment> make_pipeline_environment(const EnvironmentOptions& options) {
  if (options.source.kind == EnvironmentSource::Kind::Uniform) {
    check_rotation_and_intensity(options);
    return nullptr;
  }
  return std::make_shared<const Environment>(Environment::make(options));
}

std::string environment_summary(const EnvironmentSource& source, const Environment* e) {
  if (!e) return "uniform (radiance 0.2 x intensity)";
  const EnvTablesHeader& h = e->tables().header;
  char line[160];
  const double mb = double(e->tables().data.size() * sizeof(float)) / 1e6;
  // the built-in studio's tables come with pmr; its walls (shadows on) and images are prefiltered here
  if (e->prefilter_seconds() == 0.0)
    std::snprintf(line, sizeof line, ": %ux%u, prefiltered when pmr was built (%.1f MB of tables)", h.levels[0].width,
                  h.levels[0].height, mb);
  else
    std::snprintf(line, sizeof line, ": %ux%u, prefiltered in %.2f s (%.1f MB of tables)", h.levels[0].width,
                  h.levels[0].height, e->prefilter_seconds(), mb);
  const size_t lights = e->distant_lights().size();
  if (lights > 0)
    return printable_text(source.name()) + line + ", " + std::to_string(lights) +
           " region(s) taken out as shadowed lights";
  return printable_text(source.name()) + line;
}

void Environment::set_rotation(double deg) {
  double d = std::fmod(deg, 360.0);
  if (d < 0) d += 360.0;
  double c, s;
  if (d == 0.0) c = 1, s = 0;
  else if (d == 90.0) c = 0, s = 1;
  else if (d == 180.0) c = -1, s = 0;
  else if (d == 270.0) c = 0, s = -1;
  else c = std::cos(d * kPi / 180.0), s = std::sin(d * kPi / 180.0);
  tables_.header.rotation_cos = float(c);
  tables_.header.rotation_sin = float(s);
}

void Environment::set_intensity(double k) { tables_.header.intensity = float(k); }

glm::dvec3 Environment::level_sample(int level, const glm::dvec3& dir) const {
  const EnvTablesHeader& h = tables_.header;
  level = std::clamp(level, 0, int(h.sheen_first) + PMR_SHEEN_LEVELS - 1);
  const glm::dvec3 d = unit_or_up(dir);
  // The map turned by +angle reads the image at the direction turned by -angle.
  const double c = h.rotation_cos, s = h.rotation_sin;
  const double x = c * d.x - s * d.z, y = d.y, z = s * d.x + c * d.z;
  const double u = 0.5 + std::atan2(x, -z) / (2.0 * kPi), v = std::acos(std::clamp(y, -1.0, 1.0)) / kPi;
  const EnvLevel& l = h.levels[level];
  return double(h.intensity) *
         environment_level_bilinear(tables_.data.data() + l.offset, int(l.width), int(l.height), u, v);
}

glm::dvec3 Environment::radiance(const glm::dvec3& d) const { return level_sample(0, d); }

glm::dvec3 Environment::irradiance(const glm::dvec3& n) const {
  return level_sample(int(tables_.header.level_count) - 1, n);
}

glm::dvec3 Environment::prefiltered(const glm::dvec3& d, double r) const {
  const double c = environment_level_coordinate(r);
  const int last = int(tables_.header.level_count) - 1;
  const int l0 = std::clamp(int(std::floor(c)), 0, last - 1);
  const double f = std::clamp(c - l0, 0.0, 1.0);
  if (f == 0.0) return level_sample(l0, d);
  if (f == 1.0) return level_sample(l0 + 1, d);
  const glm::dvec3 a = level_sample(l0, d), b = level_sample(l0 + 1, d);
  glm::dvec3 p;
  for (int ch = 0; ch < 3; ++ch)
    p[ch] = l0 >= 1 && a[ch] > 0.0 && b[ch] > 0.0 ? a[ch] * std::pow(b[ch] / a[ch], f)  // geometric
                                                  : (1.0 - f) * a[ch] + f * b[ch];
  return p;
}

glm::dvec3 Environment::sheen(const glm::dvec3& d, double s) const {
  const double c =
      std::log(sheen_roughness(s) / kSheenMinRoughness) / std::log(1.0 / kSheenMinRoughness) * (PMR_SHEEN_LEVELS - 1);
  const int l0 = std::min(int(c), PMR_SHEEN_LEVELS - 2), first = int(tables_.header.sheen_first);
  const double f = c - l0;
  return (1.0 - f) * level_sample(first + l0, d) + f * level_sample(first + l0 + 1, d);
}

}  // namespace pmr
