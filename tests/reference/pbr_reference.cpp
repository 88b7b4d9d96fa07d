#include "reference/pbr_reference.h"

#include <algorithm>
#include <cmath>

namespace pmr::ref {

namespace {

constexpr double kPi = 3.14159265358979323846;

double clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

// F0 = mix(dielectric, base, metallic), the dielectric's ((ior - 1) / (ior + 1))^2 (0.04 at ior 1.5)
// times KHR_materials_specular's colour (at most 1) and weight
glm::dvec3 f0_of(const glm::dvec3& base, double metallic, double ior, double specular = 1.0,
                 const glm::dvec3& specular_color = glm::dvec3(1.0)) {
  const double f = (ior - 1.0) / (ior + 1.0);
  return glm::mix(glm::min(f * f * specular_color, glm::dvec3(1.0)) * specular, base, metallic);
}

double f90_of(double metallic, double specular) { return specular + (1.0 - specular) * metallic; }

}  // namespace

glm::dvec3 brdf_cos(const glm::dvec3& base, double metallic, double r, const glm::dvec3& n, const glm::dvec3& v,
                    const glm::dvec3& l, double ior, double transmission, double specular,
                    const glm::dvec3& specular_color, double anisotropy, const glm::dvec3& anisotropy_t,
                    double iridescence, const glm::dvec3& iridescence_F) {
  const double nl = clamp01(glm::dot(n, l));
  if (nl <= 0.0) return glm::dvec3(0.0);
  const double nv = clamp01(glm::dot(n, v));
  const glm::dvec3 hv = l + v;
  const glm::dvec3 h = glm::length(hv) > 0.0 ? glm::normalize(hv) : n;
  const double nh = clamp01(glm::dot(n, h)), vh = clamp01(glm::dot(v, h));
  const double alpha = r * r, a2 = alpha * alpha;
  const glm::dvec3 f0 = f0_of(base, metallic, ior, specular, specular_color);
  const glm::dvec3 F =
      glm::mix(f0 + (f90_of(metallic, specular) - f0) * std::pow(1.0 - vh, 5.0), iridescence_F, iridescence);
  const double dd = nh * nh * (a2 - 1.0) + 1.0;
  const double D = a2 / (kPi * dd * dd);
  const double s = nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  double dv = D * (s > 0.0 ? 0.5 / s : 0.0);
  const glm::dvec3 bt = glm::cross(n, anisotropy_t);
  if (anisotropy > 0.0 && glm::length(bt) > 0.0) {
    const glm::dvec3 t = anisotropy_t, b = glm::normalize(bt);
    const double at = glm::mix(alpha, 1.0, anisotropy * anisotropy), ab = alpha;
    const double x = glm::dot(t, h) / at, y = glm::dot(b, h) / ab, q = x * x + y * y + nh * nh;
    const double Da = 1.0 / (kPi * at * ab * q * q);
    const double gv = nl * glm::length(glm::dvec3(at * glm::dot(t, v), ab * glm::dot(b, v), nv)),
                 gl = nv * glm::length(glm::dvec3(at * glm::dot(t, l), ab * glm::dot(b, l), nl));
    dv = Da * (gv + gl > 0.0 ? 0.5 / (gv + gl) : 0.0);
  }
  const glm::dvec3 c_diff = base * (1.0 - metallic) * (1.0 - transmission);
  return ((1.0 - F) * c_diff / kPi + F * dv) * nl;
}

glm::dvec3 btdf_light(const glm::dvec3& f0, double f90, double r, double ior, const glm::dvec3& n, const glm::dvec3& v,
                      const glm::dvec3& l) {
  const glm::dvec3 lm = l - 2.0 * glm::dot(n, l) * n, hv = lm + v;
  const glm::dvec3 h = glm::length(hv) > 0.0 ? glm::normalize(hv) : n;
  const double rt = std::max(r * std::clamp(2.0 * ior - 2.0, 0.0, 1.0), 0.03), a2 = std::pow(rt, 4.0);
  const double nh = clamp01(glm::dot(n, h)), vh = clamp01(glm::dot(v, h));
  const double nl = clamp01(glm::dot(n, lm)), nv = clamp01(glm::dot(n, v));
  const glm::dvec3 F = f0 + (f90 - f0) * std::pow(1.0 - vh, 5.0);
  const double dd = nh * nh * (a2 - 1.0) + 1.0;
  const double s = nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  return (1.0 - F) * (a2 / (kPi * dd * dd)) * (s > 0.0 ? 0.5 / s : 0.0);
}

double ggx_lobe_cos(double r, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l) {
  const double nl = clamp01(glm::dot(n, l));
  if (nl <= 0.0) return 0.0;
  const double nv = clamp01(glm::dot(n, v));
  const glm::dvec3 hv = l + v;
  const glm::dvec3 h = glm::length(hv) > 0.0 ? glm::normalize(hv) : n;
  const double nh = clamp01(glm::dot(n, h)), a2 = std::pow(r, 4.0);
  const double dd = nh * nh * (a2 - 1.0) + 1.0;
  const double s = nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  return a2 / (kPi * dd * dd) * (s > 0.0 ? 0.5 / s : 0.0) * nl;
}

double sheen_lobe_cos(double s, const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l) {
  const double nl = clamp01(glm::dot(n, l));
  if (nl <= 0.0) return 0.0;
  const double nv = std::max(clamp01(glm::dot(n, v)), 1e-4), a = s * s;  // PMR_SHEEN_MIN_COS
  const glm::dvec3 hv = l + v;
  const glm::dvec3 h = glm::length(hv) > 0.0 ? glm::normalize(hv) : n;
  const double nh = clamp01(glm::dot(n, h)), sin_h = std::sqrt(std::max(0.0, 1.0 - nh * nh));
  const double D = (2.0 + 1.0 / a) * std::pow(sin_h, 1.0 / a) / (2.0 * kPi);
  auto fit = [a](double x) {
    const double o = (1.0 - a) * (1.0 - a);
    const double A = glm::mix(21.5473, 25.3245, o), B = glm::mix(3.82987, 3.32435, o),
                 C = glm::mix(0.19823, 0.16801, o), Dd = glm::mix(-1.97760, -1.27393, o),
                 E = glm::mix(-4.32054, -4.85967, o);
    return A / (1.0 + B * std::pow(x, C)) + Dd * x + E;
  };
  auto lambda = [&](double x) { return x < 0.5 ? std::exp(fit(x)) : std::exp(2.0 * fit(0.5) - fit(1.0 - x)); };
  const double V = std::min(1.0, 1.0 / ((1.0 + lambda(nv) + lambda(nl)) * 4.0 * nv * nl));
  return D * V * nl;
}

namespace {

// The extension's evalSensitivity: the thin film's spectral term for optical path difference opd (nm)
// and phase shifts `shift`, in Rec. 709.
glm::dvec3 film_sensitivity(double opd, const glm::dvec3& shift) {
  const double phase = 2.0 * kPi * opd * 1.0e-9, p2 = phase * phase;
  const glm::dvec3 val(5.4856e-13, 4.4201e-13, 5.2481e-13), pos(1.6810e6, 1.7953e6, 2.2084e6),
      var(4.3278e9, 9.3046e9, 6.6121e9);
  glm::dvec3 xyz;
  for (int c = 0; c < 3; ++c)
    xyz[c] = val[c] * std::sqrt(2.0 * kPi * var[c]) * std::cos(pos[c] * phase + shift[c]) * std::exp(-p2 * var[c]);
  xyz.x +=
      9.7470e-14 * std::sqrt(2.0 * kPi * 4.5282e9) * std::cos(2.2399e6 * phase + shift[0]) * std::exp(-4.5282e9 * p2);
  xyz /= 1.0685e-7;
  const glm::dmat3 xyz_to_rec709(3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259, -0.4985314,
                                 0.0415560, 1.0572252);
  return xyz_to_rec709 * xyz;
}

double schlick(double r0, double cos) { return r0 + (1.0 - r0) * std::pow(1.0 - cos, 5.0); }

}  // namespace

glm::dvec3 thin_film_fresnel(double outside, double film, double cos1, double d, const glm::dvec3& f0) {
  const double t = std::clamp(d / 0.03, 0.0, 1.0), ior = outside + (film - outside) * t * t * (3.0 - 2.0 * t);
  const double sin2sq = std::pow(outside / ior, 2.0) * (1.0 - cos1 * cos1), cos2sq = 1.0 - sin2sq;
  if (cos2sq < 0.0) return glm::dvec3(1.0);  // total internal reflection
  const double cos2 = std::sqrt(cos2sq);
  const double R12 = schlick(std::pow((ior - outside) / (ior + outside), 2.0), cos1), T121 = 1.0 - R12;
  const double phi21 = kPi - (ior < outside ? kPi : 0.0), opd = 2.0 * ior * d * cos2;
  glm::dvec3 R23(0.0), phi(0.0);
  for (int c = 0; c < 3; ++c) {
    const double s0 = std::sqrt(std::clamp(f0[c], 0.0, 0.9999)), base = (1.0 + s0) / (1.0 - s0);
    R23[c] = schlick(std::pow((base - ior) / (base + ior), 2.0), cos2);
    phi[c] = phi21 + (base < ior ? kPi : 0.0);
  }
  const glm::dvec3 R123 = glm::clamp(R12 * R23, 1e-5, 0.9999), r123 = glm::sqrt(R123);
  const glm::dvec3 Rs = T121 * T121 * R23 / (1.0 - R123);
  glm::dvec3 I = R12 + Rs, Cm = Rs - T121;
  for (int m = 1; m <= 2; ++m) {
    Cm *= r123;
    I += Cm * 2.0 * film_sensitivity(m * opd, double(m) * phi);
  }
  return glm::max(I, glm::dvec3(0.0));
}

glm::dvec3 light_irradiance(const PunctualLight& light, const glm::dvec3& p, glm::dvec3& l) {
  if (light.type == LightType::Directional) {
    l = -light.direction;
    return light.color_intensity;
  }
  const glm::dvec3 d = light.position - p;
  const double dist = glm::length(d);
  if (!(dist > 0.0)) {
    l = glm::dvec3(0.0);
    return glm::dvec3(0.0);
  }
  l = d / dist;
  double w = 1.0 / (dist * dist);
  if (light.range > 0.0) w *= clamp01(1.0 - std::pow(dist / light.range, 4.0));
  if (light.type == LightType::Spot) {
    const double c = glm::dot(light.direction, -l);
    w *= std::pow(clamp01((c - light.cos_outer) / std::max(0.001, light.cos_inner - light.cos_outer)), 2.0);
  }
  return light.color_intensity * w;
}

// the largest finite half: brighter colours saturate there (cl/shade.h)
constexpr double kHalfMax = 65504.0;

glm::dvec3 pbr_color(const SurfacePoint& s, const std::vector<PunctualLight>& lights, const EnvironmentTerms& env,
                     double exposure) {
  if (s.unlit) return glm::min(exposure * s.base, glm::dvec3(kHalfMax));
  const double r = std::min(1.0, std::max(0.03, s.roughness));
  const glm::dvec3 v = glm::normalize(s.eye - s.p);
  const glm::dvec3 f0 = f0_of(s.base, s.metallic, s.ior, s.specular, s.specular_color);
  const double f90 = f90_of(s.metallic, s.specular);
  glm::dvec3 film(0.0);  // under a clear coat the film's outside is the coat (ior 1.5)
  if (s.iridescence > 0.0)
    film = thin_film_fresnel(s.clearcoat > 0.0 ? 1.5 : 1.0, s.iridescence_ior, clamp01(glm::dot(s.n, v)),
                             s.iridescence_thickness, f0);
  // the sheen's scalings of what lies beneath it, from the view and from a light (1 without sheen)
  const double sheen_max = std::max({s.sheen_color.x, s.sheen_color.y, s.sheen_color.z});
  const double rs = std::min(1.0, std::max(0.07, s.sheen_roughness)), nv0 = clamp01(glm::dot(s.n, v));
  const double e_v = sheen_max > 0.0 ? env.sheen_albedo(nv0, rs) : 0.0, view_scale = clamp01(1.0 - sheen_max * e_v);
  glm::dvec3 sum(0.0), under(0.0);  // the lights' reflection; what the view's scaling applies to
  for (const PunctualLight& light : lights) {
    glm::dvec3 l;
    const glm::dvec3 E = light_irradiance(light, s.p, l);
    glm::dvec3 f = brdf_cos(s.base, s.metallic, r, s.n, v, l, s.ior, s.transmission, s.specular, s.specular_color,
                            s.anisotropy, s.anisotropy_t, s.iridescence, film);
    if (sheen_max > 0.0) {
      const double e_l = env.sheen_albedo(clamp01(glm::dot(s.n, l)), rs);
      f = f * clamp01(1.0 - sheen_max * std::max(e_v, e_l)) + s.sheen_color * sheen_lobe_cos(rs, s.n, v, l);
    }
    sum += f * E;
    if (s.transmission > 0.0)
      under +=
          s.transmission * (s.base * (1.0 - s.metallic)) * s.attenuation * btdf_light(f0, f90, r, s.ior, s.n, v, l) * E;
  }
  const glm::dvec3 c_diff = s.base * (1.0 - s.metallic);
  const glm::dvec2 ab = env.split_sum(clamp01(glm::dot(s.n, v)), r);
  glm::dvec3 reflected = glm::reflect(-v, s.n);
  const glm::dvec3 bt = glm::cross(s.n, s.anisotropy_t);
  if (s.anisotropy > 0.0 && glm::length(bt) > 0.0) {  // the bent normal
    const glm::dvec3 b = glm::normalize(bt), bent_to = glm::cross(glm::cross(b, v), b);
    const double bend = std::pow(1.0 - s.anisotropy * (1.0 - r), 4.0);
    reflected = glm::reflect(-v, glm::normalize(glm::mix(bent_to, s.n, bend)));
  }
  const glm::dvec3 specular = glm::mix(f0 * ab.x + f90 * ab.y, film * (ab.x + ab.y), s.iridescence);
  under += s.ao * ((1.0 - s.transmission) * c_diff * env.irradiance(s.n) + specular * env.prefiltered(reflected, r));
  under += s.ao * s.transmission * (1.0 - specular) * c_diff * s.through;
  glm::dvec3 color = sum + (under + s.emissive) * view_scale;
  if (sheen_max > 0.0) color += s.ao * s.sheen_color * e_v * env.sheen(glm::reflect(-v, s.n), rs);
  if (s.clearcoat > 0.0) {
    const double rc = std::min(1.0, std::max(0.03, s.clearcoat_roughness)), nv = glm::dot(s.clearcoat_n, v);
    glm::dvec3 coat(0.0);
    for (const PunctualLight& light : lights) {
      glm::dvec3 l;
      const glm::dvec3 E = light_irradiance(light, s.p, l);
      coat += ggx_lobe_cos(rc, s.clearcoat_n, v, l) * E;
    }
    const glm::dvec2 cab = env.split_sum(clamp01(nv), rc);
    coat += s.ao * (cab.x + cab.y) * env.prefiltered(glm::reflect(-v, s.clearcoat_n), rc);
    const double w = s.clearcoat * (0.04 + 0.96 * std::pow(1.0 - std::min(1.0, std::abs(nv)), 5.0));
    color = color * (1.0 - w) + coat * w;
  }
  return glm::min(exposure * color, glm::dvec3(kHalfMax));  // saturates like the kernels' halves
}

}  // namespace pmr::ref
