// Bounds-checked reading of glTF accessors: any legal component type, normalized or not, any byte
// stride, sparse substitution, and accessors without a bufferView (zeros). Every offset is checked in
// 64-bit arithmetic against the bufferView before anything is allocated or read, so the memory used is
// bounded by the data actually present in the file.
#include <cstring>

#include "scene/gltf_internal.h"

namespace pmr::gltf {
namespace {

constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE;              // 5120
constexpr int kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;    // 5121
constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;            // 5122
constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;  // 5123
constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;      // 5125
constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;            // 5126

// An accessor with no bufferView is all zeros (plus sparse values): nothing in the file bounds its
// count, so cap it well above any real mesh instead of allocating whatever the JSON asks for.
constexpr uint64_t kMaxImplicitElements = uint64_t(1) << 24;

// Allowed (componentType, normalized) pairs as a bit set: bit 2 * (componentType - 5120) + normalized.
constexpr uint32_t combo(int component_type, bool normalized) {
  return uint32_t(1) << (2 * (component_type - kByte) + (normalized ? 1 : 0));
}

struct Rule {
  const char* name;
  uint32_t types;   // bit n set: n components (SCALAR = 1 .. VEC4 = 4) allowed
  uint32_t combos;  // see combo()
};

// Core glTF 2.0 plus KHR_mesh_quantization (which only adds integer forms of the same attributes).
const Rule kPosition{"POSITION", 1u << 3,
                     combo(kFloat, false) | combo(kByte, false) | combo(kByte, true) | combo(kUByte, false) |
                         combo(kUByte, true) | combo(kShort, false) | combo(kShort, true) | combo(kUShort, false) |
                         combo(kUShort, true)};
const Rule kNormal{"NORMAL", 1u << 3, combo(kFloat, false) | combo(kByte, true) | combo(kShort, true)};
// TANGENT: xyz unit, w the handedness (+-1); KHR_mesh_quantization adds normalized byte and short.
const Rule kTangent{"TANGENT", 1u << 4, combo(kFloat, false) | combo(kByte, true) | combo(kShort, true)};
const Rule kTexcoord{"TEXCOORD", 1u << 2,
                     combo(kFloat, false) | combo(kUByte, true) | combo(kUShort, true) | combo(kByte, false) |
                         combo(kByte, true) | combo(kUByte, false) | combo(kShort, false) | combo(kShort, true) |
                         combo(kUShort, false)};
const Rule kColor{"COLOR", 1u << 3 | 1u << 4, combo(kFloat, false) | combo(kUByte, true) | combo(kUShort, true)};
const Rule kIndices{"indices", 1u << 1, combo(kUByte, false) | combo(kUShort, false) | combo(kUInt, false)};
// Animation samplers: key times are float scalars; outputs float or normalized integers (rotations and
// weights may be quantized), scalar (weights), VEC3 (translation, scale) or VEC4 (rotation).
const Rule kKeyTimes{"animation input", 1u << 1, combo(kFloat, false)};
const Rule kAnimationOutput{
    "animation output", 1u << 1 | 1u << 3 | 1u << 4,
    combo(kFloat, false) | combo(kByte, true) | combo(kUByte, true) | combo(kShort, true) | combo(kUShort, true)};
// Skins: JOINTS_n are unsigned byte / short indices, WEIGHTS_n float or normalized unsigned integers,
// inverse bind matrices float MAT4. Morph target deltas: float, or (KHR_mesh_quantization) integers.
const Rule kJoints{"JOINTS", 1u << 4, combo(kUByte, false) | combo(kUShort, false)};
const Rule kWeights{"WEIGHTS", 1u << 4, combo(kFloat, false) | combo(kUByte, true) | combo(kUShort, true)};
const Rule kInverseBind{"inverseBindMatrices", 1u << 16, combo(kFloat, false)};
const Rule kMorphDelta{
    "morph target", 1u << 3,
    combo(kFloat, false) | combo(kByte, false) | combo(kByte, true) | combo(kShort, false) | combo(kShort, true)};

size_t component_size(int type) {
  switch (type) {
    case kByte:
    case kUByte:
      return 1;
    case kShort:
    case kUShort:
      return 2;
    case kUInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT4:
      return 16;  // float MAT4 columns are 16 bytes: no padding (spec, "Data Alignment")
    default:
      return 0;  // MAT2 / MAT3 are never read
  }
}

std::string type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "type " + std::to_string(type);
  }
}

std::string component_name(int type) {
  switch (type) {
    case kByte:
      return "BYTE";
    case kUByte:
      return "UNSIGNED_BYTE";
    case kShort:
      return "SHORT";
    case kUShort:
      return "UNSIGNED_SHORT";
    case kUInt:
      return "UNSIGNED_INT";
    case kFloat:
      return "FLOAT";
    default:
      return std::to_string(type);
  }
}

// One component as a float, normalized integers per the glTF 2.0 spec's formulas (unsigned: c / max,
// signed: max(c / max, -1), so that -128 and -32768 map to -1 like -127 and -32767).
float read_component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case kByte: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0f, -1.0f) : float(v);
    }
    case kUByte: {
      uint8_t v = *p;
      return normalized ? v / 255.0f : float(v);
    }
    case kShort: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case kUShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : float(v);
    }
    case kUInt: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return float(v);
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }  // kFloat (the rule admits nothing else)
  }
}

uint32_t read_index(const unsigned char* p, int type) {
  switch (type) {
    case kUByte:
      return *p;
    case kUShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }  // kUInt
  }
}

// The validated layout of one accessor. data == nullptr: no bufferView, the elements are zeros.
struct Layout {
  const tinygltf::Accessor* accessor = nullptr;
  std::string label;  // "accessor 3 (POSITION of mesh 0 primitive 1)"
  int components = 0;
  size_t element_size = 0;
  size_t stride = 0;
  const unsigned char* data = nullptr;
};

// [offset, offset + length) inside a bufferView of `available` bytes, overflow-safe.
bool fits(uint64_t offset, uint64_t length, uint64_t available) {
  uint64_t end = 0;
  return !__builtin_add_overflow(offset, length, &end) && end <= available;
}

Layout resolve(const tinygltf::Model& m, int index, const Rule& rule, const std::string& what,
               const std::string& file) {
  Layout l;
  l.label = "accessor " + std::to_string(index) + " (" + what + ")";
  if (index < 0 || size_t(index) >= m.accessors.size())
    fail(file, l.label + " does not exist (the file has " + std::to_string(m.accessors.size()) + " accessors)");
  const tinygltf::Accessor& a = *(l.accessor = &m.accessors[size_t(index)]);
  l.components = component_count(a.type);
  if (l.components == 0 || !(rule.types >> l.components & 1u))
    fail(file, l.label + " has type " + type_name(a.type) + ", which " + rule.name + " does not allow");
  if (component_size(a.componentType) == 0 || !(rule.combos & combo(a.componentType, a.normalized)))
    fail(file, l.label + " has componentType " + component_name(a.componentType) +
                   (a.normalized ? " (normalized)" : "") + ", which " + rule.name + " does not allow");
  l.element_size = component_size(a.componentType) * size_t(l.components);
  if (a.bufferView < 0) {
    if (a.count > kMaxImplicitElements)
      fail(file, l.label + " has no bufferView and count " + std::to_string(a.count) + "; more than " +
                     std::to_string(kMaxImplicitElements) + " implicit zero elements are not supported");
    return l;
  }
  if (size_t(a.bufferView) >= m.bufferViews.size())
    fail(file, l.label + " refers to bufferView " + std::to_string(a.bufferView) +
                   ", which does not exist (the file has " + std::to_string(m.bufferViews.size()) + ")");
  const tinygltf::BufferView& bv = m.bufferViews[size_t(a.bufferView)];  // inside its buffer: validate_model
  l.stride = bv.byteStride != 0 ? bv.byteStride : l.element_size;
  if (l.stride < l.element_size)
    fail(file, l.label + " reads " + std::to_string(l.element_size) + "-byte elements but bufferView " +
                   std::to_string(a.bufferView) + " has byteStride " + std::to_string(l.stride));
  if (a.count > 0) {
    // byteOffset + stride * (count - 1) + element size <= byteLength (glTF spec, "Data Alignment")
    uint64_t span = 0;
    if (__builtin_mul_overflow(uint64_t(l.stride), uint64_t(a.count - 1), &span) ||
        __builtin_add_overflow(span, uint64_t(l.element_size), &span) || !fits(a.byteOffset, span, bv.byteLength))
      fail(file, l.label + " overruns bufferView " + std::to_string(a.bufferView) + ": count " +
                     std::to_string(a.count) + " with byteStride " + std::to_string(l.stride) + " from byteOffset " +
                     std::to_string(a.byteOffset) + " does not fit in its " + std::to_string(bv.byteLength) + " bytes");
  }
  l.data = m.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + a.byteOffset;
  return l;
}

// Calls put(element, bytes) for each sparse substitution, after checking the sparse block completely.
// Sparse indices and values are tightly packed (the spec forbids byteStride on their bufferViews).
template <class Put>
void apply_sparse(const tinygltf::Model& m, const Layout& l, const std::string& file, Put put) {
  const tinygltf::Accessor& a = *l.accessor;
  if (!a.sparse.isSparse) return;
  const int count = a.sparse.count;
  if (count < 1 || uint64_t(count) > a.count)
    fail(file, l.label + " has sparse.count " + std::to_string(count) + ", outside 1.." + std::to_string(a.count));
  auto view = [&](int index, int offset, uint64_t element, const char* part) -> const unsigned char* {
    const std::string name = l.label + " sparse " + part;
    if (index < 0 || size_t(index) >= m.bufferViews.size())
      fail(file, name + " refers to bufferView " + std::to_string(index) + ", which does not exist");
    if (offset < 0) fail(file, name + " has a negative byteOffset");
    const tinygltf::BufferView& bv = m.bufferViews[size_t(index)];
    if (!fits(uint64_t(offset), uint64_t(count) * element, bv.byteLength))  // count < 2^31, element <= 16
      fail(file, name + " overruns bufferView " + std::to_string(index) + ": " + std::to_string(count) + " x " +
                     std::to_string(element) + " bytes from byteOffset " + std::to_string(offset) + " do not fit in " +
                     std::to_string(bv.byteLength));
    return m.buffers[size_t(bv.buffer)].data.data() + bv.byteOffset + size_t(offset);
  };
  const int index_type = a.sparse.indices.componentType;
  if (index_type != kUByte && index_type != kUShort && index_type != kUInt)
    fail(file, l.label + " sparse indices have componentType " + component_name(index_type) +
                   " (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT expected)");
  const size_t index_size = component_size(index_type);
  const unsigned char* indices = view(a.sparse.indices.bufferView, a.sparse.indices.byteOffset, index_size, "indices");
  const unsigned char* values = view(a.sparse.values.bufferView, a.sparse.values.byteOffset, l.element_size, "values");
  for (size_t k = 0; k < size_t(count); ++k) {
    const uint32_t target = read_index(indices + k * index_size, index_type);
    if (target >= a.count)
      fail(file, l.label + " has sparse index " + std::to_string(target) + " but only " + std::to_string(a.count) +
                     " elements");
    put(target, values + k * l.element_size);
  }
}

const Rule& rule_for(Semantic semantic) {
  switch (semantic) {
    case Semantic::Position:
      return kPosition;
    case Semantic::Normal:
      return kNormal;
    case Semantic::Tangent:
      return kTangent;
    case Semantic::Texcoord:
      return kTexcoord;
    case Semantic::Color:
      return kColor;
    case Semantic::KeyTimes:
      return kKeyTimes;
    case Semantic::AnimationOutput:
      return kAnimationOutput;
    case Semantic::Joints:
      return kJoints;
    case Semantic::Weights:
      return kWeights;
    case Semantic::InverseBind:
      return kInverseBind;
    case Semantic::MorphDelta:
      return kMorphDelta;
    default:
      return kIndices;
  }
}

}  // namespace

uint64_t decoded_bytes(const tinygltf::Model& m, int accessor) {
  if (accessor < 0 || size_t(accessor) >= m.accessors.size()) return 0;
  const tinygltf::Accessor& a = m.accessors[size_t(accessor)];
  const int n = component_count(a.type);
  return uint64_t(a.count) * uint64_t(n > 0 ? n : 16) * 4;  // MAT2 / MAT3 (never read) as MAT4
}

void check_accessor(const tinygltf::Model& m, int accessor, Semantic semantic, const std::string& what,
                    const std::string& file) {
  resolve(m, accessor, rule_for(semantic), what, file);
}

AttributeData read_attribute(const tinygltf::Model& m, int accessor, Semantic semantic, const std::string& what,
                             const std::string& file) {
  const Layout l = resolve(m, accessor, rule_for(semantic), what, file);
  const tinygltf::Accessor& a = *l.accessor;
  AttributeData out;
  out.count = a.count;
  out.components = l.components;
  out.values.assign(a.count * size_t(l.components), 0.0f);  // bounded by the checks in resolve()
  const size_t csize = component_size(a.componentType);
  auto decode = [&](size_t element, const unsigned char* p) {
    float* dst = &out.values[element * size_t(l.components)];
    for (int c = 0; c < l.components; ++c)
      dst[c] = read_component(p + size_t(c) * csize, a.componentType, a.normalized);
  };
  if (l.data)
    for (size_t i = 0; i < a.count; ++i) decode(i, l.data + i * l.stride);
  apply_sparse(m, l, file, decode);
  return out;
}

std::vector<uint32_t> read_indices(const tinygltf::Model& m, int accessor, const std::string& what,
                                   const std::string& file) {
  const Layout l = resolve(m, accessor, kIndices, what, file);
  const tinygltf::Accessor& a = *l.accessor;
  std::vector<uint32_t> out(a.count, 0u);
  if (l.data)
    for (size_t i = 0; i < a.count; ++i) out[i] = read_index(l.data + i * l.stride, a.componentType);
  apply_sparse(m, l, file, [&](size_t i, const unsigned char* p) { out[i] = read_index(p, a.componentType); });
  return out;
}

}  // namespace pmr::gltf
