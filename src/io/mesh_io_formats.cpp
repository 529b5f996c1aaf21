// OFF, PLY and STL readers. These are written here rather than taken from OpenMesh because OpenMesh's
// readers drop faces with bad indices without a word, size their arrays from the header counts (a
// hostile header allocates gigabytes), duplicate vertices of non-manifold faces and never say on which
// line a file went wrong. Every count is checked against the bytes that are really there before
// anything is allocated, and every error names the line (text) or the element (binary).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

#include <sffd/error.h>
#include "io/io_util.h"
#include "io/mesh_io_internal.h"

namespace sffd::meshio {
namespace {

std::string countText(uint64_t n, const char* what) { return std::to_string(n) + " " + what; }

// ---------------------------------------------------------------------------------------------------
// OFF: "[ST][C][N]OFF", "nV nF [nE]", nV lines "x y z [nx ny nz] [colour] [s t]", nF lines "n i1 .. in [colour]".
// '#' starts a comment. Indices are 0-based.

}  // namespace

Mesh readOff(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  io::LineReader lines(text);
  std::vector<std::string_view> tok;
  std::string_view raw;
  size_t line = 0;
  // Next line with tokens (comments stripped); false at the end.
  auto nextTokens = [&]() {
    while (lines.next(raw, line)) {
      size_t hash = raw.find('#');
      io::splitTokens(hash == std::string_view::npos ? raw : raw.substr(0, hash), tok);
      if (!tok.empty()) return true;
    }
    return false;
  };
  if (!nextTokens()) throw inputError(path, 0, "no OFF header");
  std::string_view head = tok[0];
  if (head.size() < 3 || head.substr(head.size() - 3) != "OFF") throw inputError(path, line, "not an OFF file (expected 'OFF')");
  std::string_view prefix = head.substr(0, head.size() - 3);
  bool hasNormals = false;
  for (char c : prefix) {
    if (c == 'N') hasNormals = true;
    else if (c == '4' || c == 'n') throw inputError(path, line, "4-dimensional / n-dimensional OFF is not supported");
    else if (c != 'S' && c != 'T' && c != 'C') throw inputError(path, line, "unknown OFF variant " + io::quoted(head));
  }
  size_t first = 1;
  if (tok.size() > 1 && tok[1] == "BINARY") throw inputError(path, line, "binary OFF is not supported");
  if (tok.size() == 1) {
    if (!nextTokens()) throw inputError(path, line, "missing vertex and face counts");
    first = 0;
  }
  if (tok.size() < first + 2) throw inputError(path, line, "expected vertex and face counts");
  long long nv = 0, nf = 0;
  if (!io::parseInt(tok[first], nv) || nv < 0) throw inputError(path, line, "bad vertex count " + io::quoted(tok[first]));
  if (!io::parseInt(tok[first + 1], nf) || nf < 0) throw inputError(path, line, "bad face count " + io::quoted(tok[first + 1]));
  if (uint64_t(nv) > kMaxVertices) throw inputError(path, line, "too many vertices");
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line at least 8: no more can be in the file.
  uint64_t rest = text.size() - lines.offset();
  if (uint64_t(nv) > rest / 6 + 1 || uint64_t(nf) > rest / 8 + 1)
    throw inputError(path, line, "header declares " + countText(nv, "vertices") + " and " + countText(nf, "faces") +
                                     ", more than the file can hold (truncated?)");
  if (nf == 0) throw inputError(path, line, "no faces");

  Mesh mesh;
  mesh.positions.reserve(size_t(nv));
  std::vector<uint8_t> fromFile;
  if (hasNormals) {
    mesh.normals.reserve(size_t(nv));
    fromFile.assign(size_t(nv), 1);
  }
  for (long long v = 0; v < nv; ++v) {
    if (!nextTokens())
      throw inputError(path, line, "file ends after " + std::to_string(v) + " of " + countText(nv, "vertices"));
    size_t need = hasNormals ? 6 : 3;
    if (tok.size() < need) throw inputError(path, line, "vertex line needs " + std::to_string(need) + " numbers");
    double d[6];
    for (size_t c = 0; c < need; ++c) {
      if (!io::parseDouble(tok[c], d[c])) throw inputError(path, line, "bad number " + io::quoted(tok[c]));
      if (c < 3 && !std::isfinite(d[c])) throw inputError(path, line, "non-finite coordinate " + io::quoted(tok[c]));
    }
    mesh.positions.push_back({d[0], d[1], d[2]});
    if (hasNormals) mesh.normals.push_back({d[3], d[4], d[5]});
  }
  std::vector<uint32_t> poly;
  mesh.triangles.reserve(size_t(nf));
  for (long long f = 0; f < nf; ++f) {
    if (!nextTokens()) throw inputError(path, line, "file ends after " + std::to_string(f) + " of " + countText(nf, "faces"));
    long long n = 0;
    if (!io::parseInt(tok[0], n)) throw inputError(path, line, "bad face vertex count " + io::quoted(tok[0]));
    if (n < 3) throw inputError(path, line, "face with " + std::to_string(n) + " vertices (at least 3 needed)");
    if (uint64_t(n) > tok.size() - 1) throw inputError(path, line, "face declares " + std::to_string(n) + " vertices but lists fewer");
    poly.clear();
    for (long long c = 1; c <= n; ++c) {
      long long i = 0;
      if (!io::parseInt(tok[size_t(c)], i)) throw inputError(path, line, "bad vertex index " + io::quoted(tok[size_t(c)]));
      if (i < 0 || i >= nv)
        throw inputError(path, line, "vertex index " + std::to_string(i) + " out of range (" + countText(nv, "vertices") + ")");
      poly.push_back(uint32_t(i));
    }
    addPolygon(mesh, poly.data(), poly.size(), dropped);
  }
  // More lines than the header declares: faces a wrong count leaves out, or something else; either way unread.
  if (nextTokens())
    mesh.warnings.push_back(path + ":" + std::to_string(line) + ": text after the header's last face (of " + std::to_string(nf) +
                            ") ignored (is the face count wrong?)");
  noteDroppedPolygons(mesh, dropped);
  finishMesh(mesh, fromFile, path);
  return mesh;
}

// ---------------------------------------------------------------------------------------------------
// PLY (ascii, binary_little_endian, binary_big_endian). Reads element "vertex" (x y z, optional nx ny nz)
// and element "face" (list vertex_indices or vertex_index); other properties and elements are skipped.

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool plyType(std::string_view s, PlyType& t) {
  static const std::pair<const char*, PlyType> names[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},    {"uint8", PlyType::UInt8},
      {"short", PlyType::Int16},   {"int16", PlyType::Int16},     {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},
      {"int", PlyType::Int32},     {"int32", PlyType::Int32},     {"uint", PlyType::UInt32},    {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64}, {"float64", PlyType::Float64}};
  for (const auto& [n, ty] : names)
    if (s == n) {
      t = ty;
      return true;
    }
  return false;
}

size_t plySize(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8: return 1;
    case PlyType::Int16:
    case PlyType::UInt16: return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}
bool plyIsFloat(PlyType t) { return t == PlyType::Float32 || t == PlyType::Float64; }

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType countType = PlyType::UInt8, type = PlyType::Float32;
};
struct PlyElement {
  std::string name;
  uint64_t count = 0;
  size_t line = 0;
  std::vector<PlyProperty> props;
};

// Binary data with bounds checks.
struct BinaryCursor {
  const unsigned char* p;
  const unsigned char* end;
  bool swap;
  bool has(size_t n) const { return size_t(end - p) >= n; }
  double scalar(PlyType t) {
    unsigned char b[8];
    size_t n = plySize(t);
    std::memcpy(b, p, n);
    p += n;
    if (swap) std::reverse(b, b + n);
    switch (t) {
      case PlyType::Int8: { int8_t v; std::memcpy(&v, b, 1); return v; }
      case PlyType::UInt8: return b[0];
      case PlyType::Int16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::UInt16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::Int32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::UInt32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Float32: { float v; std::memcpy(&v, b, 4); return v; }
      case PlyType::Float64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
  }
};

}  // namespace

Mesh readPly(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  std::vector<size_t> ignoredHeaderLines;
  io::LineReader lines(text);
  std::string_view l;
  size_t line = 0;
  std::vector<std::string_view> tok;
  if (!lines.next(l, line) || io::trim(l) != "ply") throw inputError(path, 1, "not a PLY file (expected 'ply')");
  enum { Ascii, BinLE, BinBE, None } format = None;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (lines.next(l, line)) {
    io::splitTokens(l, tok);
    if (tok.empty()) continue;
    if (tok[0] == "end_header") {
      ended = true;
      break;
    }
    if (tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() < 3) throw inputError(path, line, "bad format line");
      if (tok[1] == "ascii") format = Ascii;
      else if (tok[1] == "binary_little_endian") format = BinLE;
      else if (tok[1] == "binary_big_endian") format = BinBE;
      else throw inputError(path, line, "unknown PLY format " + io::quoted(tok[1]));
      if (tok[2] != "1.0") throw inputError(path, line, "unsupported PLY version " + io::quoted(tok[2]));
    } else if (tok[0] == "element") {
      long long n = 0;
      if (tok.size() != 3 || !io::parseInt(tok[2], n) || n < 0) throw inputError(path, line, "bad element line");
      elements.push_back({std::string(tok[1]), uint64_t(n), line, {}});
    } else if (tok[0] == "property") {
      if (elements.empty()) throw inputError(path, line, "property before any element");
      PlyProperty p;
      if (tok.size() == 5 && tok[1] == "list") {
        p.list = true;
        if (!plyType(tok[2], p.countType) || !plyType(tok[3], p.type)) throw inputError(path, line, "unknown property type");
        if (plyIsFloat(p.countType)) throw inputError(path, line, "list count type must be an integer type");
        p.name = tok[4];
      } else if (tok.size() == 3) {
        if (!plyType(tok[1], p.type)) throw inputError(path, line, "unknown property type " + io::quoted(tok[1]));
        p.name = tok[2];
      } else {
        throw inputError(path, line, "bad property line");
      }
      elements.back().props.push_back(p);
    } else if (elements.empty() && !ended) {
      // Free text before the first element, which some old exporters wrote without "comment".
      ignoredHeaderLines.push_back(line);
    } else {
      throw inputError(path, line, "unknown header line " + io::quoted(tok[0]));
    }
  }
  if (!ended) throw inputError(path, line, "no end_header");
  if (format == None) throw inputError(path, line, "no format line");
  size_t headerLines = line;
  const size_t dataOffset = lines.offset();

  // Which properties are ours.
  const PlyElement* vertexEl = nullptr;
  const PlyElement* faceEl = nullptr;
  int px = -1, py = -1, pz = -1, pnx = -1, pny = -1, pnz = -1, pidx = -1;
  int pu = -1, pv = -1, pcolor[4] = {-1, -1, -1, -1};
  for (const auto& e : elements) {
    if (e.name == "vertex" && !vertexEl) {
      vertexEl = &e;
      for (size_t i = 0; i < e.props.size(); ++i) {
        const auto& p = e.props[i];
        const std::string& q = p.name;
        int* slot = q == "x" ? &px : q == "y" ? &py : q == "z" ? &pz : q == "nx" ? &pnx : q == "ny" ? &pny : q == "nz" ? &pnz
                  : q == "u" || q == "s" || q == "texture_u" || q == "texture_s" ? &pu
                  : q == "v" || q == "t" || q == "texture_v" || q == "texture_t" ? &pv
                  : q == "red" || q == "diffuse_red" ? &pcolor[0] : q == "green" || q == "diffuse_green" ? &pcolor[1]
                  : q == "blue" || q == "diffuse_blue" ? &pcolor[2] : q == "alpha" ? &pcolor[3] : nullptr;
        if (slot && !p.list && *slot < 0) *slot = int(i);
      }
      if (px < 0 || py < 0 || pz < 0) throw inputError(path, e.line, "element vertex lacks x, y or z");
    } else if (e.name == "face" && !faceEl) {
      faceEl = &e;
      for (size_t i = 0; i < e.props.size(); ++i)
        if (e.props[i].list && (e.props[i].name == "vertex_indices" || e.props[i].name == "vertex_index")) pidx = int(i);
      if (pidx < 0) throw inputError(path, e.line, "element face lacks a vertex_indices list");
      if (plyIsFloat(e.props[size_t(pidx)].type)) throw inputError(path, e.line, "vertex indices must have an integer type");
    }
  }
  if (!vertexEl) throw inputError(path, headerLines, "no vertex element");
  if (!faceEl || faceEl->count == 0) throw inputError(path, 0, "no faces");
  if (vertexEl->count > kMaxVertices) throw inputError(path, vertexEl->line, "too many vertices");
  const bool hasNormals = pnx >= 0 && pny >= 0 && pnz >= 0;
  const bool hasTexcoords = pu >= 0 && pv >= 0, hasColors = pcolor[0] >= 0 && pcolor[1] >= 0 && pcolor[2] >= 0;
  // Integer colours are fractions of 255 (65535 for 16-bit types); float ones are as given.
  double colorScale[4] = {1, 1, 1, 1};
  for (int c = 0; c < 4; ++c)
    if (pcolor[c] >= 0) {
      const PlyType t = vertexEl->props[size_t(pcolor[c])].type;
      colorScale[c] = plyIsFloat(t) ? 1.0 : plySize(t) == 2 ? 1.0 / 65535.0 : 1.0 / 255.0;
    }

  // Least bytes the declared elements need: a count is never trusted beyond what the file can hold.
  const uint64_t dataBytes = text.size() - dataOffset;
  {
    long double need = 0;
    for (const auto& e : elements) {
      uint64_t item = 0;
      for (const auto& p : e.props) item += format == Ascii ? 2 : (p.list ? plySize(p.countType) : plySize(p.type));
      need += (long double)e.count * (long double)item;
    }
    if (need > (long double)dataBytes)
      throw inputError(path, 0, "truncated: the header declares " + countText(vertexEl->count, "vertices") + " and " +
                                    countText(faceEl->count, "faces") + ", more than the " + std::to_string(dataBytes) +
                                    " bytes of data can hold");
  }

  Mesh mesh;
  mesh.positions.reserve(size_t(vertexEl->count));
  mesh.normals.reserve(hasNormals ? size_t(vertexEl->count) : 0);
  mesh.triangles.reserve(size_t(faceEl->count));
  std::vector<uint32_t> poly;
  std::vector<double> values;
  // The vertex whose properties are in `values`.
  auto addVertex = [&] {
    mesh.positions.push_back({values[size_t(px)], values[size_t(py)], values[size_t(pz)]});
    if (hasNormals) mesh.normals.push_back({values[size_t(pnx)], values[size_t(pny)], values[size_t(pnz)]});
    if (hasTexcoords) mesh.texcoords.push_back({values[size_t(pu)], values[size_t(pv)]});
    if (hasColors) {
      glm::dvec4 k(1.0);
      for (int c = 0; c < 4; ++c)
        if (pcolor[c] >= 0) k[c] = values[size_t(pcolor[c])] * colorScale[c];
      mesh.colors.push_back(k);
    }
  };

  if (format == Ascii) {
    io::Tokenizer tz(std::string_view(text).substr(dataOffset), headerLines + 1);
    std::string_view t;
    size_t tl = 0;
    auto number = [&](PlyType ty, const char* what, uint64_t item) {
      if (!tz.next(t, tl))
        throw inputError(path, tl ? tl : tz.line(), std::string("file ends in ") + what + " " + std::to_string(item));
      double v = 0;
      if (plyIsFloat(ty)) {
        if (!io::parseDouble(t, v)) throw inputError(path, tl, "bad number " + io::quoted(t));
      } else {
        long long i = 0;
        if (!io::parseInt(t, i)) throw inputError(path, tl, "bad integer " + io::quoted(t));
        v = double(i);
      }
      return v;
    };
    for (const auto& e : elements) {
      const bool isV = &e == vertexEl, isF = &e == faceEl;
      for (uint64_t item = 0; item < e.count; ++item) {
        values.assign(e.props.size(), 0.0);
        for (size_t pi = 0; pi < e.props.size(); ++pi) {
          const auto& p = e.props[pi];
          if (!p.list) {
            values[pi] = number(p.type, e.name.c_str(), item);
            if (isV && !std::isfinite(values[pi]) && (int(pi) == px || int(pi) == py || int(pi) == pz))
              throw inputError(path, tl, "non-finite coordinate " + io::quoted(t));
            continue;
          }
          double cnt = number(p.countType, e.name.c_str(), item);
          if (cnt < 0 || cnt > double(text.size())) throw inputError(path, tl, "bad list length " + io::quoted(t));
          const bool ours = isF && int(pi) == pidx;
          if (ours) {
            if (cnt < 3) throw inputError(path, tl, "face with " + std::to_string(int64_t(cnt)) + " vertices (at least 3 needed)");
            poly.clear();
          }
          for (uint64_t c = 0; c < uint64_t(cnt); ++c) {
            double v = number(p.type, e.name.c_str(), item);
            if (ours) {
              if (v < 0 || v >= double(vertexEl->count))
                throw inputError(path, tl, "vertex index " + io::formatNumber(v) + " out of range (" +
                                               countText(vertexEl->count, "vertices") + ")");
              poly.push_back(uint32_t(v));
            }
          }
        }
        if (isV) {
          addVertex();
        } else if (isF) {
          addPolygon(mesh, poly.data(), poly.size(), dropped);
        }
      }
    }
  } else {
    BinaryCursor cur{reinterpret_cast<const unsigned char*>(text.data()) + dataOffset,
                     reinterpret_cast<const unsigned char*>(text.data()) + text.size(), format == BinBE};
    auto truncated = [&](const PlyElement& e, uint64_t item) {
      return inputError(path, 0, "truncated: data ends in " + e.name + " " + std::to_string(item) + " of " + std::to_string(e.count));
    };
    for (const auto& e : elements) {
      const bool isV = &e == vertexEl, isF = &e == faceEl;
      for (uint64_t item = 0; item < e.count; ++item) {
        values.assign(e.props.size(), 0.0);
        for (size_t pi = 0; pi < e.props.size(); ++pi) {
          const auto& p = e.props[pi];
          if (!p.list) {
            if (!cur.has(plySize(p.type))) throw truncated(e, item);
            values[pi] = cur.scalar(p.type);
            continue;
          }
          if (!cur.has(plySize(p.countType))) throw truncated(e, item);
          double cnt = cur.scalar(p.countType);
          if (cnt < 0) throw inputError(path, 0, e.name + " " + std::to_string(item) + ": negative list length");
          if (!cur.has(size_t(cnt) * plySize(p.type))) throw truncated(e, item);
          const bool ours = isF && int(pi) == pidx;
          if (ours) {
            if (cnt < 3)
              throw inputError(path, 0, "face " + std::to_string(item) + " has " + std::to_string(int64_t(cnt)) +
                                            " vertices (at least 3 needed)");
            poly.clear();
          }
          for (uint64_t c = 0; c < uint64_t(cnt); ++c) {
            double v = cur.scalar(p.type);
            if (ours) {
              if (v < 0 || v >= double(vertexEl->count))
                throw inputError(path, 0, "face " + std::to_string(item) + ": vertex index " + io::formatNumber(v) +
                                              " out of range (" + countText(vertexEl->count, "vertices") + ")");
              poly.push_back(uint32_t(v));
            }
          }
        }
        if (isV) {
          glm::dvec3 q{values[size_t(px)], values[size_t(py)], values[size_t(pz)]};
          if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
            throw inputError(path, 0, "vertex " + std::to_string(item) + ": non-finite coordinate");
          addVertex();
        } else if (isF) {
          addPolygon(mesh, poly.data(), poly.size(), dropped);
        }
      }
    }
  }
  std::vector<uint8_t> fromFile(hasNormals ? mesh.positions.size() : 0, 1);
  noteDroppedPolygons(mesh, dropped);
  if (!ignoredHeaderLines.empty())
    mesh.warnings.push_back(path + ":" + std::to_string(ignoredHeaderLines[0]) + ": " +
                            std::to_string(ignoredHeaderLines.size()) + " free-text header line" +
                            (ignoredHeaderLines.size() == 1 ? "" : "s") + " without \"comment\" ignored");
  finishMesh(mesh, fromFile, path);
  return mesh;
}

// ---------------------------------------------------------------------------------------------------
// STL, ASCII and binary. Vertices are welded by exact position (as OpenMesh does); STL facet normals are
// not vertex normals, so normals are computed (normalsFromFile = false).

namespace {

bool startsWithSolid(const std::string& text) {
  size_t i = 0;
  while (i < text.size() && io::isSpace(text[i])) ++i;
  return text.compare(i, 5, "solid") == 0;
}

struct Welder {
  Key3Map ids;   // key: bitsKey of the position
  Mesh* mesh;
  const std::string& path;
  uint32_t add(const glm::dvec3& p) {
    const uint32_t next = uint32_t(mesh->positions.size());
    const uint32_t id = ids.of(bitsKey(p), next);
    if (id == next) {
      if (next >= kMaxVertices) throw inputError(path, 0, "too many vertices");
      mesh->positions.push_back(p + glm::dvec3(0.0));   // -0 kept as +0
    }
    return id;
  }
};

Mesh readStlBinary(const std::string& path, const std::string& text) {
  if (text.size() < 84)
    throw inputError(path, 0, "too short for a binary STL (" + std::to_string(text.size()) + " bytes, the header alone is 84)");
  uint32_t n = 0;
  std::memcpy(&n, text.data() + 80, 4);   // little-endian on every platform this builds on
  uint64_t expect = 84 + 50 * uint64_t(n);
  if (expect != text.size())
    throw inputError(path, 0, std::string(expect > text.size() ? "truncated binary STL" : "binary STL with trailing data") +
                                  ": the header declares " + countText(n, "triangles") + " (" + std::to_string(expect) +
                                  " bytes), the file has " + std::to_string(text.size()) + " bytes");
  if (n == 0) throw inputError(path, 0, "no triangles");
  Mesh mesh;
  Welder w{Key3Map(n / 2 + 1), &mesh, path};
  mesh.triangles.reserve(n);
  const char* p = text.data() + 84;
  for (uint32_t t = 0; t < n; ++t, p += 50) {
    std::array<uint32_t, 3> tri;
    for (int c = 0; c < 3; ++c) {
      float f[3];
      std::memcpy(f, p + 12 + 12 * c, 12);
      if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]))
        throw inputError(path, 0, "triangle " + std::to_string(t) + ": non-finite coordinate");
      tri[c] = w.add({f[0], f[1], f[2]});
    }
    mesh.triangles.push_back(tri);
  }
  finishMesh(mesh, {}, path);
  return mesh;
}

Mesh readStlAscii(const std::string& path, const std::string& text) {
  size_t dropped = 0;   // polygons without area (addPolygon)
  size_t polygonFacets = 0, firstPolygonFacet = 0;   // facets of more than 3 vertices (STL says 3)
  io::Tokenizer tz(text);
  std::string_view t;
  size_t line = 1;
  Mesh mesh;
  Welder w{Key3Map(0), &mesh, path};
  std::vector<uint32_t> poly;
  auto expect = [&](const char* word) {
    if (!tz.next(t, line)) throw inputError(path, line, std::string("file ends, expected '") + word + "' (truncated?)");
    if (t != word) throw inputError(path, line, std::string("expected '") + word + "', found " + io::quoted(t));
  };
  auto number = [&]() {
    if (!tz.next(t, line)) throw inputError(path, line, "file ends, expected a number (truncated?)");
    double d = 0;
    if (!io::parseDouble(t, d)) throw inputError(path, line, "bad number " + io::quoted(t));
    if (!std::isfinite(d)) throw inputError(path, line, "non-finite coordinate " + io::quoted(t));
    return d;
  };
  expect("solid");
  tz.restOfLine();   // the solid's name
  bool inSolid = true;
  while (true) {
    if (!tz.next(t, line)) {
      if (inSolid) throw inputError(path, line, "file ends before 'endsolid' (truncated?)");
      break;
    }
    if (!inSolid) {
      if (t != "solid") throw inputError(path, line, "expected 'solid' or the end of the file, found " + io::quoted(t));
      tz.restOfLine();
      inSolid = true;
      continue;
    }
    if (t == "endsolid") {
      tz.restOfLine();
      inSolid = false;
      continue;
    }
    if (t != "facet") throw inputError(path, line, "expected 'facet' or 'endsolid', found " + io::quoted(t));
    size_t facetLine = line;
    expect("normal");
    for (int c = 0; c < 3; ++c) {
      if (!tz.next(t, line)) throw inputError(path, line, "file ends in a facet normal (truncated?)");
      double d;
      if (!io::parseDouble(t, d)) throw inputError(path, line, "bad number " + io::quoted(t));   // value unused
    }
    expect("outer");
    expect("loop");
    poly.clear();
    while (true) {
      if (!tz.next(t, line)) throw inputError(path, line, "file ends in a facet (truncated?)");
      if (t == "endloop") break;
      if (t != "vertex") throw inputError(path, line, "expected 'vertex' or 'endloop', found " + io::quoted(t));
      glm::dvec3 p;
      p.x = number();
      p.y = number();
      p.z = number();
      if (mesh.positions.size() >= kMaxVertices) throw inputError(path, line, "too many vertices");
      poly.push_back(w.add(p));
    }
    if (poly.size() < 3)
      throw inputError(path, facetLine, "facet with " + std::to_string(poly.size()) + " vertices (at least 3 needed)");
    expect("endfacet");
    if (poly.size() > 3 && !polygonFacets++) firstPolygonFacet = facetLine;
    addPolygon(mesh, poly.data(), poly.size(), dropped);
  }
  noteDroppedPolygons(mesh, dropped);
  if (polygonFacets)
    mesh.warnings.push_back(path + ":" + std::to_string(firstPolygonFacet) + ": " + std::to_string(polygonFacets) +
                            (polygonFacets == 1 ? " facet has" : " facets have") +
                            " more than 3 vertices (STL facets are triangles): read as polygons");
  finishMesh(mesh, {}, path);
  return mesh;
}

}  // namespace

Mesh readStl(const std::string& path, const std::string& text) {
  // ASCII files start with "solid"; so do some binary ones (their 80-byte header is free text). Such a
  // file is binary when its size is exactly 84 + 50 n for the count at byte 80 and it does not read as
  // ASCII text (a NUL byte, or no "endsolid").
  // A file that does not start with "solid" but is not binary either: UTF-16 text is named as such.
  bool ascii = startsWithSolid(text);
  bool sizeFits = false;
  if (text.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, text.data() + 80, 4);
    sizeFits = 84 + 50 * uint64_t(n) == text.size();
  }
  const bool hasNul = std::memchr(text.data(), '\0', text.size()) != nullptr;
  if (ascii && text.size() >= 84) {
    bool looksText = !hasNul && text.find("endsolid") != std::string::npos;
    if (sizeFits && !looksText) ascii = false;
    // Neither size fits nor text: a binary STL with a "solid" header, cut short or padded; reported as
    // binary (its sizes), not as an ASCII syntax error.
    if (!sizeFits && hasNul) ascii = false;
  }
  if (!ascii && !sizeFits && text.size() >= 2 &&
      (text.compare(0, 2, "\xFF\xFE") == 0 || text.compare(0, 2, "\xFE\xFF") == 0)) {
    std::string copy = text.substr(0, 4);
    io::checkTextEncoding(path, copy, true);   // throws: UTF-16 (or UTF-32) text
  }
  return ascii ? readStlAscii(path, text) : readStlBinary(path, text);
}

}  // namespace sffd::meshio
