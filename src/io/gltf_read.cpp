// glTF 2.0 reader on tinygltf (Debian's libtinygltf-dev): tinygltf parses the JSON, the GLB container,
// data URIs and external buffers; this file walks the default scene and turns its triangle primitives
// into one Mesh. Every accessor is bounds-checked against its buffer before it is read.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <sffd/error.h>

#include "io/gltf_io.h"
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

// Images are passed through by URI, never decoded.
bool keepImageUndecoded(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

// External buffers are read only from regular files (not a FIFO or /dev/zero, which would never end),
// and file names are taken as written (tinygltf's default expands them like a shell).
bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (err) *err += "cannot read " + path + ": not a regular file\n";
    return false;
  }
  try {
    const std::string bytes = io::readWholeFile(path);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const Error& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}
std::string pathAsWritten(const std::string& path, void*) { return path; }
bool fileExists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}
bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "not written\n";
  return false;
}

class Reader {
 public:
  Reader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

  Mesh read() {
    if (m_.scenes.empty()) throw inputError(path_, 0, "no scene");
    const int scene = m_.defaultScene >= 0 ? m_.defaultScene : 0;
    if (size_t(scene) >= m_.scenes.size()) throw inputError(path_, 0, "default scene " + std::to_string(scene) + " does not exist");
    for (int node : m_.scenes[size_t(scene)].nodes) visit(node, glm::dmat4(1.0), 0);
    if (skipped_ > 0)
      mesh_.warnings.push_back(path_ + ": " + std::to_string(skipped_) + " point or line primitive" + (skipped_ == 1 ? "" : "s") + " skipped");
    if (mesh_.triangles.empty()) throw inputError(path_, 0, "no triangles in the default scene");
    for (const tinygltf::Material& gm : m_.materials) mesh_.materials.push_back(materialOf(gm));
    if (!anyTexcoord_) mesh_.texcoords.clear();
    if (!anyColor_) mesh_.colors.clear();
    if (!anyMaterial_) mesh_.triangleMaterial.clear();
    if (mesh_.materials.empty()) mesh_.triangleMaterial.clear();
    finishMesh(mesh_, fromFile_, path_);
    return std::move(mesh_);
  }

 private:
  Material materialOf(const tinygltf::Material& gm) const {
    Material mat;
    mat.name = gm.name;
    const auto& f = gm.pbrMetallicRoughness.baseColorFactor;
    for (size_t c = 0; c < 4 && c < f.size(); ++c) mat.baseColor[int(c)] = f[c];
    const int t = gm.pbrMetallicRoughness.baseColorTexture.index;
    if (t >= 0 && size_t(t) < m_.textures.size()) {
      const int source = m_.textures[size_t(t)].source;
      if (source >= 0 && size_t(source) < m_.images.size()) {
        const tinygltf::Image& image = m_.images[size_t(source)];
        mat.baseColorTexture = image.uri;
        if (image.uri.empty() && image.bufferView >= 0) {
          mat.baseColorImage = bytesOfView(image.bufferView, "image");
          mat.baseColorImageMime = image.mimeType;
        }
      }
    }
    return mat;
  }

  std::vector<uint8_t> bytesOfView(int index, const char* what) const {
    if (index < 0 || size_t(index) >= m_.bufferViews.size()) throw inputError(path_, 0, std::string(what) + ": no such buffer view");
    const tinygltf::BufferView& v = m_.bufferViews[size_t(index)];
    if (v.buffer < 0 || size_t(v.buffer) >= m_.buffers.size()) throw inputError(path_, 0, std::string(what) + ": no such buffer");
    const std::vector<unsigned char>& b = m_.buffers[size_t(v.buffer)].data;
    if (v.byteOffset > b.size() || v.byteLength > b.size() - v.byteOffset) throw inputError(path_, 0, std::string(what) + ": reaches beyond its buffer");
    return std::vector<uint8_t>(b.begin() + ptrdiff_t(v.byteOffset), b.begin() + ptrdiff_t(v.byteOffset + v.byteLength));
  }

  glm::dmat4 localMatrix(const tinygltf::Node& n) const {
    if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());   // column-major, as glTF stores it
    glm::dmat4 m(1.0);
    if (n.translation.size() == 3) m = glm::translate(m, glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
    if (n.rotation.size() == 4) m *= glm::mat4_cast(glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]));
    if (n.scale.size() == 3) m = glm::scale(m, glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
    return m;
  }

  void visit(int index, const glm::dmat4& parent, int depth) {
    if (index < 0 || size_t(index) >= m_.nodes.size()) throw inputError(path_, 0, "node " + std::to_string(index) + " does not exist");
    if (depth > 64) throw inputError(path_, 0, "nodes nested deeper than 64 (a cycle?)");
    const tinygltf::Node& n = m_.nodes[size_t(index)];
    const glm::dmat4 world = parent * localMatrix(n);
    if (n.mesh >= 0) {
      if (size_t(n.mesh) >= m_.meshes.size()) throw inputError(path_, 0, "mesh " + std::to_string(n.mesh) + " does not exist");
      for (const tinygltf::Primitive& p : m_.meshes[size_t(n.mesh)].primitives) addPrimitive(p, world);
    }
    for (int child : n.children) visit(child, world, depth + 1);
  }

  // Accessor `index` as `components` doubles per element (normalized integers scaled to [0, 1]).
  std::vector<double> values(int index, int components, const char* what) const {
    if (index < 0 || size_t(index) >= m_.accessors.size()) throw inputError(path_, 0, std::string(what) + ": no such accessor");
    const tinygltf::Accessor& a = m_.accessors[size_t(index)];
    const std::string where = std::string(what) + " (accessor " + std::to_string(index) + ")";
    if (a.sparse.isSparse) throw inputError(path_, 0, where + ": sparse accessors are not supported");
    if (tinygltf::GetNumComponentsInType(uint32_t(a.type)) != components)
      throw inputError(path_, 0, where + ": expected " + std::to_string(components) + " components");
    if (a.bufferView < 0) {   // all zeros, as the specification says
      if (a.count > kMaxVertices) throw inputError(path_, 0, where + ": too many elements");
      return std::vector<double>(a.count * size_t(components), 0.0);
    }
    if (size_t(a.bufferView) >= m_.bufferViews.size()) throw inputError(path_, 0, where + ": no such buffer view");
    const tinygltf::BufferView& v = m_.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= m_.buffers.size()) throw inputError(path_, 0, where + ": no such buffer");
    const std::vector<unsigned char>& buffer = m_.buffers[size_t(v.buffer)].data;
    const int componentBytes = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (componentBytes <= 0) throw inputError(path_, 0, where + ": bad component type");
    const size_t element = size_t(componentBytes) * size_t(components);
    const size_t stride = v.byteStride ? v.byteStride : element;
    const size_t first = v.byteOffset + a.byteOffset;
    // Every size is checked against the buffer's before it is multiplied: no overflow, no allocation
    // beyond what the file holds.
    const bool fits = v.byteOffset <= buffer.size() && v.byteLength <= buffer.size() - v.byteOffset && a.byteOffset <= v.byteLength &&
                      stride <= buffer.size() && a.count <= buffer.size() &&
                      (a.count == 0 || (a.count - 1) * stride + element <= v.byteLength - a.byteOffset);
    if (!fits) throw inputError(path_, 0, where + ": reaches beyond its buffer");
    std::vector<double> out(a.count * size_t(components), 0.0);
    for (size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < components; ++c) {
        const unsigned char* b = buffer.data() + first + i * stride + size_t(c * componentBytes);
        double d = 0;
        switch (a.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, b, 4); d = f; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: d = a.normalized ? b[0] / 255.0 : b[0]; break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t s; std::memcpy(&s, b, 2); d = a.normalized ? s / 65535.0 : s; break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, b, 4); d = u; break; }
          case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t s; std::memcpy(&s, b, 1); d = a.normalized ? std::max(s / 127.0, -1.0) : s; break; }
          case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t s; std::memcpy(&s, b, 2); d = a.normalized ? std::max(s / 32767.0, -1.0) : s; break; }
          default: throw inputError(path_, 0, where + ": bad component type");
        }
        if (!std::isfinite(d)) throw inputError(path_, 0, where + ": non-finite value");
        out[i * size_t(components) + size_t(c)] = d;
      }
    return out;
  }

  int attribute(const tinygltf::Primitive& p, const char* name) const {
    auto it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
  }

  void addPrimitive(const tinygltf::Primitive& p, const glm::dmat4& world) {
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_;
      return;
    }
    const int position = attribute(p, "POSITION");
    if (position < 0) throw inputError(path_, 0, "a triangle primitive without POSITION");
    const std::vector<double> xyz = values(position, 3, "POSITION");
    const size_t n = xyz.size() / 3, base = mesh_.positions.size();
    if (base + n > kMaxVertices) throw inputError(path_, 0, "too many vertices");
    const glm::dmat3 normalMatrix = glm::inverseTranspose(glm::dmat3(world));
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0;   // a mirroring transform turns the winding
    const int normal = attribute(p, "NORMAL"), uv = attribute(p, "TEXCOORD_0"), color = attribute(p, "COLOR_0");
    const std::vector<double> nrm = normal >= 0 ? values(normal, 3, "NORMAL") : std::vector<double>();
    const std::vector<double> tex = uv >= 0 ? values(uv, 2, "TEXCOORD_0") : std::vector<double>();
    int colorComponents = 4;
    if (color >= 0 && size_t(color) < m_.accessors.size() && m_.accessors[size_t(color)].type == TINYGLTF_TYPE_VEC3) colorComponents = 3;
    const std::vector<double> rgba = color >= 0 ? values(color, colorComponents, "COLOR_0") : std::vector<double>();
    for (const auto* a : {&nrm, &tex, &rgba})
      if (!a->empty() && a->size() / (a == &tex ? 2 : a == &rgba ? size_t(colorComponents) : 3) != n)
        throw inputError(path_, 0, "a primitive's attributes differ in count from its POSITION");
    for (size_t i = 0; i < n; ++i) {
      mesh_.positions.push_back(glm::dvec3(world * glm::dvec4(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], 1.0)));
      mesh_.normals.push_back(nrm.empty() ? glm::dvec3(0.0) : normalMatrix * glm::dvec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]));
      fromFile_.push_back(!nrm.empty());
      // glTF's texture origin is the image's upper left, OBJ's (and Mesh's) the lower left.
      mesh_.texcoords.push_back(tex.empty() ? glm::dvec2(0.0) : glm::dvec2(tex[2 * i], 1.0 - tex[2 * i + 1]));
      glm::dvec4 k(1.0);
      for (int c = 0; !rgba.empty() && c < colorComponents; ++c) k[c] = rgba[i * size_t(colorComponents) + size_t(c)];
      mesh_.colors.push_back(k);
    }
    anyTexcoord_ = anyTexcoord_ || !tex.empty();
    anyColor_ = anyColor_ || !rgba.empty();
    std::vector<double> index;
    if (p.indices >= 0) {
      index = values(p.indices, 1, "indices");
    } else {
      for (size_t i = 0; i < n; ++i) index.push_back(double(i));
    }
    for (double i : index)
      if (i >= double(n)) throw inputError(path_, 0, "vertex index " + io::formatNumber(i) + " out of range (" + std::to_string(n) + " vertices)");
    auto add = [&](size_t a, size_t b, size_t c) {
      if (mirrored) std::swap(b, c);
      mesh_.triangles.push_back({uint32_t(base + size_t(index[a])), uint32_t(base + size_t(index[b])), uint32_t(base + size_t(index[c]))});
      mesh_.triangleMaterial.push_back(p.material >= 0 && size_t(p.material) < m_.materials.size() ? uint32_t(p.material) : Mesh::kNoIndex);
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (index.size() % 3) throw inputError(path_, 0, "a triangle primitive's index count is not a multiple of 3");
      for (size_t i = 0; i + 2 < index.size(); i += 3) add(i, i + 1, i + 2);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < index.size(); ++i) i % 2 ? add(i + 1, i, i + 2) : add(i, i + 1, i + 2);
    } else {
      for (size_t i = 1; i + 1 < index.size(); ++i) add(0, i, i + 1);
    }
    anyMaterial_ = anyMaterial_ || p.material >= 0;
  }

  const std::string& path_;
  const tinygltf::Model& m_;
  Mesh mesh_;
  std::vector<uint8_t> fromFile_;
  size_t skipped_ = 0;
  bool anyTexcoord_ = false, anyColor_ = false, anyMaterial_ = false;
};

}  // namespace

Mesh readGltf(const std::string& path, const std::string& bytes) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keepImageUndecoded, nullptr);
  loader.SetFsCallbacks(tinygltf::FsCallbacks{fileExists, pathAsWritten, readRegularFile, refuseWrite, nullptr});
  tinygltf::Model model;
  std::string err, warn;
  // Never empty: tinygltf joins it with each buffer's uri, and an empty one would let an absolute uri
  // ("/etc/passwd") name a file outside the model's folder when the model is in the current folder only.
  std::string baseDir = std::filesystem::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  const bool glb = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                    unsigned(bytes.size()), baseDir)
                      : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir);
  if (!ok) {
    std::string what = err.empty() ? "not a glTF 2.0 file" : err.substr(0, err.find('\n'));
    throw inputError(path, 0, io::oneLine(what));
  }
  return Reader(path, model).read();
}

}  // namespace sffd::meshio
