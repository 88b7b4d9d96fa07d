// Double-precision reference of the physically based shading model (--shading pbr, docs/SHADING.md):
// the glTF metallic-roughness BRDF, punctual lights and the colour assembly, evaluated exactly as the
// model states them (the kernels' cl/brdf.h computes the same in float).
#pragma once
#include <functional>
#include <vector>

#include <glm/glm.hpp>

namespace pmr::ref {

// f(l, v) * dot(n, l) for unit n, v, l; r = the clamped roughness (alpha = r^2); the dielectric's F0
// from its index of refraction ((ior - 1) / (ior + 1))^2 (KHR_materials_ior; 0.04 at glTF's 1.5); the
// diffuse lobe weighted by 1 - transmission (KHR_materials_transmission: that part transmits instead).
// KHR_materials_specular's weight and colour scale the dielectric's Fresnel term: F0 = mix(min(f0_ior
// colour, 1) weight, base, metallic), F90 = mix(weight, 1, metallic), F = F0 + (F90 - F0) (1 - v.h)^5.
// KHR_materials_anisotropy (strength s > 0, unit direction t): GGX with alpha_t = mix(alpha, 1, s^2)
// along t and alpha_b = alpha along b = normalize(cross(n, t)), and its height-correlated visibility.
glm::dvec3 brdf_cos(const glm::dvec3& base, double metallic, double r, const glm::dvec3& n, const glm::dvec3& v,
                    const glm::dvec3& l, double ior = 1.5, double transmission = 0.0, double specular = 1.0,
                    const glm::dvec3& specular_color = glm::dvec3(1.0), double anisotropy = 0.0,
                    const glm::dvec3& anisotropy_t = glm::dvec3(1.0, 0.0, 0.0), double iridescence = 0.0,
                    const glm::dvec3& iridescence_F = glm::dvec3(0.0));

// KHR_materials_iridescence's Fresnel term of a thin film (the extension's implementation notes): film
// of ior `film` and thickness d nm between `outside` and a base of Fresnel F0 f0, seen at cos1 = n.v;
// the film's ior eases to `outside` over the first 0.03 nm, as the Sample Viewer's. In the BRDF
// F = mix(Schlick's F, this, iridescence).
glm::dvec3 thin_film_fresnel(double outside, double film, double cos1, double d, const glm::dvec3& f0);

// KHR_materials_transmission's BTDF for a light in direction l seen through the surface: (1 - F(v.h))
// D(n.h) Vis(n.l', n.v), l' = l mirrored on the surface's plane, h = normalize(l' + v), GGX of roughness
// max(r clamp(2 ior - 2, 0, 1), 0.03).
glm::dvec3 btdf_light(const glm::dvec3& f0, double f90, double r, double ior, const glm::dvec3& n, const glm::dvec3& v,
                      const glm::dvec3& l);

enum class LightType { Directional = 0, Point = 1, Spot = 2 };

struct PunctualLight {
  LightType type = LightType::Directional;
  glm::dvec3 color_intensity{1.0};       // colour x intensity
  glm::dvec3 position{0.0};              // world space (point, spot)
  glm::dvec3 direction{0.0, 0.0, -1.0};  // unit, the direction the light travels (the node's -Z)
  double range = 0.0;                    // 0: none
  double cos_inner = 1.0, cos_outer = 0.0;
};

// Irradiance on a surface facing the light at p, and the unit direction toward it.
glm::dvec3 light_irradiance(const PunctualLight& light, const glm::dvec3& p, glm::dvec3& l);

// The material inputs at a surface point and how it is seen.
struct SurfacePoint {
  glm::dvec3 base{1.0};                    // base colour (rgb)
  double metallic = 0.0, roughness = 1.0;  // roughness before clamping
  double ior = 1.5;                        // KHR_materials_ior
  double transmission = 0.0;               // KHR_materials_transmission
  glm::dvec3 through{0.0};                 // the light arriving through it (transmission_reference.h)
  glm::dvec3 attenuation{1.0};             // ... and its Beer-Lambert factor, which the lights take too
  glm::dvec3 n{0.0, 0.0, 1.0};             // unit shading normal (back faces already flipped)
  glm::dvec3 p{0.0};                       // world position
  glm::dvec3 eye{0.0, 0.0, 1.0};           // the view's camera position (world)
  double ao = 1.0;
  glm::dvec3 emissive{0.0};
  bool unlit = false;
  // KHR_materials_clearcoat: intensity, roughness (before clamping) and the coat's unit normal (its
  // own normal map applied, or the interpolated one; back faces already flipped)
  double clearcoat = 0.0, clearcoat_roughness = 0.0;
  glm::dvec3 clearcoat_n{0.0, 0.0, 1.0};
  double specular = 1.0;  // KHR_materials_specular: weight and colour (factor x texture)
  glm::dvec3 specular_color{1.0};
  double anisotropy = 0.0;                 // KHR_materials_anisotropy: strength (factor x texture B) and
  glm::dvec3 anisotropy_t{1.0, 0.0, 0.0};  // the unit direction in world space (strength 0: isotropic)
  double iridescence = 0.0;                // KHR_materials_iridescence: factor x texture R, film ior,
  double iridescence_ior = 1.3, iridescence_thickness = 400.0;  // thickness in nm
  glm::dvec3 sheen_color{0.0};   // KHR_materials_sheen: colour (factor x texture; 0: none) and roughness
  double sheen_roughness = 0.0;  // (factor x texture A, before clamping to [0.07, 1])
};

// KHR_materials_sheen's lobe D V n.l (the extension's implementation notes: the Charlie distribution and
// visibility, V at most 1) for the clamped sheen roughness s and unit n, v, l, n.v read at least 1e-4 (at
// 0 exactly V's clamp makes the lobe jump); 0 where n.l <= 0.
double sheen_lobe_cos(double s, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l);

// The environment's precomputed terms: I(n) (irradiance / pi), P(d, r) and the split-sum (A, B).
struct EnvironmentTerms {
  std::function<glm::dvec3(const glm::dvec3&)> irradiance;
  std::function<glm::dvec3(const glm::dvec3&, double)> prefiltered;
  std::function<glm::dvec2(double, double)> split_sum;         // (dot(n, v), r) -> (A, B)
  std::function<glm::dvec3(const glm::dvec3&, double)> sheen;  // S(d, s): the Charlie-prefiltered levels
  std::function<double(double, double)> sheen_albedo;          // (dot(n, v), s) -> E, the sheen's albedo
};

// exposure x (sum over lights of f E dot(n, l) + ao (c_diff I(n) + (F0 A + F90 B) P(reflect(-v, n), r)) + e);
// an anisotropic surface reflects the environment about the bent normal normalize(mix(cross(cross(b, v),
// b), n, (1 - s (1 - r))^4)) instead of n;
// unlit: exposure x base. With transmission T, the diffuse terms are weighted by 1 - T, and
// ao T (1 - (F0 A + B)) c_diff `through` is added (KHR_materials_transmission's BTDF, DESIGN 4c), and
// per light T c_diff `attenuation` (1 - F) D Vis E, the GGX lobe about the light mirrored on the
// surface (btdf_light).
// D(n.h) Vis(n.l, n.v) n.l of GGX with roughness r (alpha = r^2), no Fresnel: the clear coat's lobe.
double ggx_lobe_cos(double r, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l);

// With a clear coat of intensity c (KHR_materials_clearcoat's fresnel_coat, ior 1.5) that colour C
// becomes C (1 - c Fc) + c Fc (sum over lights of ggx_lobe_cos(rc, nc) E + ao (A + B)(nc.v, rc)
// P(reflect(-v, nc), rc)), Fc = 0.04 + 0.96 (1 - |nc.v|)^5, rc the clamped coat roughness, nc its
// normal.
// With a sheen of colour c (KHR_materials_sheen, m = max3(c), s the clamped sheen roughness), under the
// coat: each light's f becomes f min(1 - m E(n.v), 1 - m E(n.l)) + c sheen_lobe_cos (the scalings
// clamped to [0, 1]; n.v at least 1e-4); the environment, transmission and emission terms are scaled by
// 1 - m E(n.v), and
// ao c E(n.v) S(reflect(-v, n), s) is added.
glm::dvec3 pbr_color(const SurfacePoint& s, const std::vector<PunctualLight>& lights, const EnvironmentTerms& env,
                     double exposure);

}  // namespace pmr::ref
