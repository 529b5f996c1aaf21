// glTF 2.0 writer: one node, one mesh, one primitive per material sharing the vertex attributes
// (POSITION with its bounds, NORMAL, TEXCOORD_0, COLOR_0 as float; indices uint32), materials as PBR
// base colour factor and texture URI. The JSON is built with nlohmann::json; .glb is the binary
// container (JSON and BIN chunks, 4-byte aligned).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include <sffd/error.h>

#include "io/atomic_file.h"
#include "io/gltf_io.h"
#include "io/io_util.h"

namespace sffd::meshio {
namespace {

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

constexpr int kFloat = 5126, kUint = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;

struct Builder {
  std::string bin;
  nlohmann::ordered_json views = nlohmann::ordered_json::array(), accessors = nlohmann::ordered_json::array();

  // Floats, `components` per element: a buffer view and its accessor; returns the accessor's index.
  int floats(const std::vector<float>& data, int components, const char* type, bool bounds = false) {
    const size_t count = data.size() / size_t(components);
    nlohmann::ordered_json a = {{"bufferView", view(data.data(), data.size() * 4, kArrayBuffer)}, {"componentType", kFloat},
                                {"count", count}, {"type", type}};
    if (bounds && count > 0) {
      std::vector<float> lo(data.begin(), data.begin() + components), hi = lo;
      for (size_t i = 0; i < count; ++i)
        for (int c = 0; c < components; ++c) {
          lo[size_t(c)] = std::min(lo[size_t(c)], data[i * size_t(components) + size_t(c)]);
          hi[size_t(c)] = std::max(hi[size_t(c)], data[i * size_t(components) + size_t(c)]);
        }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return int(accessors.size() - 1);
  }

  int indices(const std::vector<uint32_t>& data) {
    accessors.push_back({{"bufferView", view(data.data(), data.size() * 4, kElementArrayBuffer)},
                         {"componentType", kUint},
                         {"count", data.size()},
                         {"type", "SCALAR"}});
    return int(accessors.size() - 1);
  }

  int view(const void* data, size_t bytes, int target) {
    bin.append(static_cast<const char*>(data), bytes);
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size() - bytes}, {"byteLength", bytes}, {"target", target}});
    bin.resize((bin.size() + 3) & ~size_t(3), '\0');   // the next view starts 4-byte aligned
    return int(views.size() - 1);
  }
};

double unit(double x) { return std::clamp(x, 0.0, 1.0); }

// Materials, with their images by URI or embedded (in `b`'s buffer) as they were read.
nlohmann::ordered_json materialsOf(const Mesh& mesh, nlohmann::ordered_json& gltf, Builder& b) {
  nlohmann::ordered_json materials = nlohmann::ordered_json::array();
  for (const Material& m : mesh.materials) {
    nlohmann::ordered_json pbr = {{"baseColorFactor", {unit(m.baseColor.r), unit(m.baseColor.g), unit(m.baseColor.b), unit(m.baseColor.a)}}};
    const bool embedded = !m.baseColorImage.empty() && !m.baseColorImageMime.empty();
    if (!m.baseColorTexture.empty() || embedded) {
      nlohmann::ordered_json image = {{"uri", m.baseColorTexture}};
      if (embedded) {
        image = {{"bufferView", b.view(m.baseColorImage.data(), m.baseColorImage.size(), 0)}, {"mimeType", m.baseColorImageMime}};
        b.views.back().erase("target");
      }
      gltf["images"].push_back(image);
      gltf["textures"].push_back({{"source", gltf["images"].size() - 1}});
      pbr["baseColorTexture"] = {{"index", gltf["textures"].size() - 1}};
    }
    nlohmann::ordered_json j = {{"pbrMetallicRoughness", pbr}};
    if (!m.name.empty()) j["name"] = m.name;
    materials.push_back(j);
  }
  return materials;
}

}  // namespace

void writeGltf(const std::string& path, const Mesh& mesh) { writeGltfAnimation(path, {mesh}, 0); }

void writeGltfAnimation(const std::string& path, const std::vector<Mesh>& frames, double fps) {
  const Mesh& mesh = frames.at(0);
  const bool glb = io::lowerExtension(path) == ".glb";
  const size_t n = mesh.positions.size();
  Builder b;
  nlohmann::ordered_json attributes;
  size_t frame = 0;   // the frame `flat` reads, for its message
  auto flat = [&](auto get, int components) {
    std::vector<float> out;
    out.reserve(n * size_t(components));
    for (size_t v = 0; v < n; ++v)
      for (int c = 0; c < components; ++c) {
        // glTF holds floats: a value past their range (a double result, a difference of two) would be an infinity.
        const double x = get(v, c);
        if (!io::withinFloatRange(x))
          throw Error(ErrorKind::Input, path + ": not written: vertex " + std::to_string(v) +
                                            (frames.size() > 1 ? " of frame " + std::to_string(frame) : std::string()) +
                                            " is not finite or beyond the range of glTF's floats (the lattice moves it that far)");
        out.push_back(float(x));
      }
    return out;
  };
  attributes["POSITION"] = b.floats(flat([&](size_t v, int c) { return mesh.positions[v][c]; }, 3), 3, "VEC3", true);
  if (!mesh.normals.empty()) attributes["NORMAL"] = b.floats(flat([&](size_t v, int c) { return mesh.normals[v][c]; }, 3), 3, "VEC3");
  if (!mesh.texcoords.empty())   // Mesh's origin is the image's lower left, glTF's the upper left
    attributes["TEXCOORD_0"] =
        b.floats(flat([&](size_t v, int c) { return c == 0 ? mesh.texcoords[v].x : 1.0 - mesh.texcoords[v].y; }, 2), 2, "VEC2");
  if (!mesh.colors.empty()) attributes["COLOR_0"] = b.floats(flat([&](size_t v, int c) { return unit(mesh.colors[v][c]); }, 4), 4, "VEC4");

  // One primitive per material (in first-use order), triangles in file order within each.
  std::map<uint32_t, std::vector<uint32_t>> byMaterial;
  std::vector<uint32_t> order;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const uint32_t m = mesh.triangleMaterial.empty() ? Mesh::kNoIndex : mesh.triangleMaterial[t];
    auto [it, fresh] = byMaterial.try_emplace(m);
    if (fresh) order.push_back(m);
    it->second.insert(it->second.end(), mesh.triangles[t].begin(), mesh.triangles[t].end());
  }
  nlohmann::ordered_json gltf = {{"asset", {{"version", "2.0"}, {"generator", "sffd"}}}, {"scene", 0},
                                 {"scenes", {{{"nodes", {0}}}}}, {"nodes", {{{"mesh", 0}}}}};
  // Morph targets: each further frame's differences from the first.
  nlohmann::ordered_json targets = nlohmann::ordered_json::array();
  for (size_t f = 1; f < frames.size(); ++f) {
    const Mesh& k = frames[f];
    frame = f;
    if (k.positions.size() != n || k.triangles != mesh.triangles || k.normals.size() != mesh.normals.size())
      throw Error(ErrorKind::Internal, path + ": animation frame " + std::to_string(f) + " has other vertices or triangles than frame 0");
    nlohmann::ordered_json t;
    t["POSITION"] = b.floats(flat([&](size_t v, int c) { return k.positions[v][c] - mesh.positions[v][c]; }, 3), 3, "VEC3", true);
    if (!mesh.normals.empty())
      t["NORMAL"] = b.floats(flat([&](size_t v, int c) { return k.normals[v][c] - mesh.normals[v][c]; }, 3), 3, "VEC3");
    targets.push_back(t);
  }
  nlohmann::ordered_json primitives = nlohmann::ordered_json::array();
  for (uint32_t m : order) {
    nlohmann::ordered_json p = {{"attributes", attributes}, {"indices", b.indices(byMaterial[m])}, {"mode", 4}};
    if (m != Mesh::kNoIndex) p["material"] = m;
    if (!targets.empty()) p["targets"] = targets;
    primitives.push_back(p);
  }
  gltf["meshes"] = {{{"primitives", primitives}}};
  if (!targets.empty()) {
    // Key f (time f / fps) has weight 1 on target f - 1 and 0 elsewhere; key 0 is the mesh itself.
    const size_t keys = frames.size(), weights = keys - 1;
    gltf["meshes"][0]["weights"] = std::vector<double>(weights, 0.0);
    std::vector<float> times, values(keys * weights, 0.0f);
    for (size_t f = 0; f < keys; ++f) {
      times.push_back(float(double(f) / fps));
      if (f > 0) values[f * weights + f - 1] = 1.0f;
    }
    const int input = b.floats(times, 1, "SCALAR", true), output = b.floats(values, 1, "SCALAR");
    b.views[size_t(b.accessors[size_t(input)]["bufferView"])].erase("target");   // animation data is no vertex buffer
    b.views[size_t(b.accessors[size_t(output)]["bufferView"])].erase("target");
    gltf["animations"] = {{{"name", "lattice"},
                           {"samplers", {{{"input", input}, {"output", output}, {"interpolation", "LINEAR"}}}},
                           {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}}}}};
  }
  if (!mesh.materials.empty()) gltf["materials"] = materialsOf(mesh, gltf, b);
  const std::string file = replacedFile(path);   // through a link: the .bin goes beside the file it names
  const std::string binName = std::filesystem::path(file).stem().string() + ".bin";
  nlohmann::ordered_json buffer = {{"byteLength", b.bin.size()}};
  if (!glb) buffer["uri"] = binName;
  gltf["buffers"] = {buffer};
  gltf["bufferViews"] = b.views;
  gltf["accessors"] = b.accessors;
  std::string json = gltf.dump();

  if (!glb) {
    // The buffer first: a .gltf never names a .bin that is not there.
    const std::string binPath = (std::filesystem::path(file).parent_path() / binName).string();
    writeFileAtomically(binPath, [&](std::ostream& os) { os.write(b.bin.data(), std::streamsize(b.bin.size())); }, true);
    writeFileAtomically(path, [&](std::ostream& os) { os << json << '\n'; }, true);
    return;
  }
  json.resize((json.size() + 3) & ~size_t(3), ' ');
  auto u32 = [](std::string& s, uint32_t v) {
    char c[4];
    std::memcpy(c, &v, 4);
    s.append(c, 4);
  };
  std::string header;
  u32(header, 0x46546C67u);   // "glTF"
  u32(header, 2);
  u32(header, uint32_t(12 + 8 + json.size() + 8 + b.bin.size()));
  u32(header, uint32_t(json.size()));
  u32(header, 0x4E4F534Au);   // "JSON"
  std::string binHeader;
  u32(binHeader, uint32_t(b.bin.size()));
  u32(binHeader, 0x004E4942u);   // "BIN\0"
  writeFileAtomically(path, [&](std::ostream& os) { os << header << json << binHeader << b.bin; }, true);
}

}  // namespace sffd::meshio
