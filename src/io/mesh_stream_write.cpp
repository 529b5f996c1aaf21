// MeshFileWriter (<sffd/mesh.h>): writeMesh's file from a mesh handed over in pieces. PLY's header names
// the vertex and face counts, known only at the end: vertices and faces go to two scratch files beside the
// output, copied after the header into the output's temporary file at end(). STL's facets go straight to
// the output (binary: the triangle count written over its placeholder at the end). Both are formatted and
// written on a thread of their own (PieceQueue) while the caller makes the next pieces; each piece is
// checked on the caller's, so that a bad vertex stops the stream at the add() that gave it.
#include <algorithm>
#include <fstream>

#include <sffd/error.h>

#include "io/atomic_file.h"
#include "io/mesh_write_records.h"
#include "io/piece_queue.h"

namespace sffd {
namespace {

enum class Mode { Gather, Ply, Stl };

constexpr size_t kFlushBytes = 1 << 20;

// A failed write (a full disk) stops the stream at once rather than at end(): the job producing the
// pieces stops at its next add().
void flushTo(std::string& buf, std::ostream& os, const std::string& path) {
  os.write(buf.data(), std::streamsize(buf.size()));
  buf.clear();
  if (!os) throw inputError(path, 0, "cannot write: write failed (disk full?)");
}

// Appends the file at `from` (a flushed scratch file) to `to`, a block at a time.
void copyFile(const std::string& from, std::ostream& to, const std::string& path) {
  std::ifstream in(from, std::ios::binary);
  std::string block(kFlushBytes, '\0');
  while (in) {
    in.read(block.data(), std::streamsize(block.size()));
    to.write(block.data(), in.gcount());
  }
  if (!in.eof()) throw inputError(path, 0, "cannot write: reading back a temporary file failed");
}

template <class T>
void append(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

}  // namespace

struct MeshFileWriter::Impl {
  std::string path, ext;
  MeshWriteOptions options;
  Mode mode = Mode::Gather;
  bool begun = false, modeKnown = false, ended = false;
  Mesh held;                      // Gather: the whole mesh; Stl: positions and normals (the facet normals); tables
  meshio::Carried has;            // from the first piece with vertices
  size_t vertices = 0, triangles = 0;
  std::unique_ptr<AtomicFile> out, vertexSpill, faceSpill;
  std::string vbuf, fbuf;
  // Streamed modes: the thread that runs write(); everything above it touches from choose() to end().
  // Last, so that it stops before the rest goes.
  std::unique_ptr<PieceQueue> writer;

  // The fields of the file, fixed by the first piece that has vertices (an empty mesh has none).
  void choose(const Mesh& piece) {
    modeKnown = true;
    has.normals = !piece.normals.empty();
    has.texcoords = !piece.texcoords.empty();
    has.colors = !piece.colors.empty();
    if (!streams(path, options, has.colors)) return;   // gathered: writeMesh decides at the end
    mode = ext == ".ply" ? Mode::Ply : Mode::Stl;
    if (mode == Mode::Ply) {
      vertexSpill = std::make_unique<AtomicFile>(path);
      faceSpill = std::make_unique<AtomicFile>(path);
    } else {
      out = std::make_unique<AtomicFile>(path, options.binary);
      out->stream() << meshio::stlHeader(options.binary, 0);   // binary: the count set at the end
    }
    writer = std::make_unique<PieceQueue>([this](const Mesh& piece) { write(piece); });
  }

  // The caller's mistakes (a piece out of order, unlike the first or with a bad index) are input errors.
  void check(const Mesh& piece, size_t first) {
    if (first != vertices)
      throw inputError(path, 0, "mesh piece out of order: add() given firstVertex " + std::to_string(first) + " after " +
                                    std::to_string(vertices) + " vertices");
    const size_t n = piece.positions.size();
    auto sized = [&](size_t count, bool want, const char* what) {
      if (count != (want && n ? n : 0))
        throw inputError(path, 0, "mesh piece has " + std::to_string(count) + " " + what + " for " + std::to_string(n) +
                                      " vertices (the first piece with vertices had " + (want ? "one each" : "none") + ")");
    };
    sized(piece.normals.size(), has.normals, "normals");
    sized(piece.texcoords.size(), has.texcoords, "texcoords");
    sized(piece.colors.size(), has.colors, "colors");
    // The largest index first (a loop that vectorizes), each triangle's only for the message.
    uint32_t most = 0;
    for (const auto& t : piece.triangles) most = std::max(most, std::max(t[0], std::max(t[1], t[2])));
    for (size_t t = 0; most >= vertices + n && t < piece.triangles.size(); ++t)
      for (uint32_t i : piece.triangles[t])
        if (i >= vertices + n)
          throw inputError(path, 0, "mesh piece's triangles[" + std::to_string(t) + "]: vertex index " + std::to_string(i) +
                                        " out of range (" + std::to_string(vertices + n) + " vertices so far)");
    auto perTriangle = [&](const std::vector<uint32_t>& index, size_t tableSize, const char* what, const char* table) {
      if (index.empty()) return;
      if (index.size() != piece.triangles.size())
        throw inputError(path, 0, "mesh piece's " + std::string(what) + " has " + std::to_string(index.size()) + " entries for " +
                                      std::to_string(piece.triangles.size()) + " triangles");
      for (size_t t = 0; t < index.size(); ++t)
        if (index[t] != Mesh::kNoIndex && index[t] >= tableSize)
          throw inputError(path, 0, "mesh piece's " + std::string(what) + "[" + std::to_string(t) + "] is " +
                                        std::to_string(index[t]) + ", not below " + std::to_string(tableSize) + " " + table +
                                        " (begin()'s tables) nor Mesh::kNoIndex");
    };
    perTriangle(piece.triangleMaterial, held.materials.size(), "triangleMaterial", "materials");
    perTriangle(piece.triangleGroup, held.groups.size(), "triangleGroup", "groups");
    for (size_t v = 0; v < n; ++v)
      meshio::checkFiniteVertex(path, vertices + v, piece.positions[v], has.normals ? &piece.normals[v] : nullptr,
                                mode == Mode::Stl && options.binary);
  }

  void add(const Mesh& piece) {
    if (writer) writer->push(piece);
    else write(piece);
    vertices += piece.positions.size();
    triangles += piece.triangles.size();
  }

  // The piece into the file (streamed modes: on the writer's thread) or the gathered mesh.
  void write(const Mesh& piece) {
    const int digits = options.significantDigits;
    const size_t n = piece.positions.size();
    switch (mode) {
      case Mode::Gather:
        append(held.positions, piece.positions), append(held.normals, piece.normals), append(held.weldId, piece.weldId);
        append(held.texcoords, piece.texcoords), append(held.colors, piece.colors);
        append(held.triangles, piece.triangles);
        append(held.triangleMaterial, piece.triangleMaterial), append(held.triangleGroup, piece.triangleGroup);
        break;
      case Mode::Ply:
        meshio::appendPlyVertices(vbuf, piece, 0, n, digits, has, options.binary);
        meshio::appendPlyFaces(fbuf, piece.triangles.data(), piece.triangles.size(), options.binary);
        if (vbuf.size() >= kFlushBytes) flushTo(vbuf, vertexSpill->stream(), path);
        if (fbuf.size() >= kFlushBytes) flushTo(fbuf, faceSpill->stream(), path);
        break;
      case Mode::Stl:
        append(held.positions, piece.positions);
        append(held.normals, piece.normals);
        meshio::appendStlFacets(vbuf, held, piece.triangles.data(), piece.triangles.size(), has.normals, digits, options.binary);
        if (vbuf.size() >= kFlushBytes) flushTo(vbuf, out->stream(), path);
        break;
    }
  }

  void end() {
    if (mode == Mode::Gather) return writeMesh(path, held, options);
    writer->drain();
    if (mode == Mode::Ply) {
      flushTo(vbuf, vertexSpill->stream(), path);
      flushTo(fbuf, faceSpill->stream(), path);
      for (AtomicFile* f : {vertexSpill.get(), faceSpill.get()})
        if (!f->stream().flush()) throw inputError(path, 0, "cannot write: write failed (disk full?)");
      out = std::make_unique<AtomicFile>(path, options.binary);
      out->stream() << meshio::plyHeader(vertices, triangles, options.significantDigits, has, options.binary);
      copyFile(vertexSpill->temporaryPath(), out->stream(), path);
      vertexSpill.reset();
      copyFile(faceSpill->temporaryPath(), out->stream(), path);
      faceSpill.reset();
    } else {
      if (options.binary && triangles > 0xFFFFFFFFull) throw Error(ErrorKind::Input, "binary STL holds at most 2^32 - 1 triangles");
      flushTo(vbuf, out->stream(), path);
      out->stream() << meshio::stlFooter(options.binary);
      if (options.binary) {
        const std::string header = meshio::stlHeader(true, triangles);
        out->stream().seekp(0);
        out->stream().write(header.data(), std::streamsize(header.size()));
      }
    }
    out->commit();
  }
};

MeshFileWriter::MeshFileWriter(const std::string& path, const MeshWriteOptions& options) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->options = options;
  impl_->ext = meshio::checkWriteTarget(path, options);
}

MeshFileWriter::~MeshFileWriter() = default;

void MeshFileWriter::begin(const Mesh& tables) {
  Impl& I = *impl_;
  if (I.begun) throw Error(ErrorKind::Input, "MeshFileWriter: begin() called twice");
  I.begun = true;
  I.held.materials = tables.materials;
  I.held.groups = tables.groups;
  I.held.materialLibraries = tables.materialLibraries;
  I.held.weldIdIsLocation = tables.weldIdIsLocation;
  I.held.normalsFromFile = tables.normalsFromFile;
}

void MeshFileWriter::add(const Mesh& piece, size_t firstVertex) {
  Impl& I = *impl_;
  // Out of order, nothing is chosen (no file made) before check() says so.
  if (!I.begun || I.ended) throw Error(ErrorKind::Input, "MeshFileWriter: add() outside begin() and end()");
  if (!I.modeKnown && !piece.positions.empty()) I.choose(piece);
  I.check(piece, firstVertex);
  I.add(piece);
}

void MeshFileWriter::end() {
  Impl& I = *impl_;
  if (!I.begun || I.ended) throw Error(ErrorKind::Input, "MeshFileWriter: end() without begin(), or twice");
  I.ended = true;
  if (!I.modeKnown) I.choose(Mesh{});   // no vertices at all
  I.end();
}

size_t MeshFileWriter::vertexCount() const { return impl_->vertices; }
size_t MeshFileWriter::triangleCount() const { return impl_->triangles; }

bool MeshFileWriter::streams(const std::string& path, const MeshWriteOptions& options, bool colors) {
  const std::string ext = meshio::checkWriteTarget(path, options);
  return ext == ".stl" || (ext == ".ply" && !colors);
}

size_t MeshFileWriter::heldBytesPerVertex(const std::string& path, const MeshWriteOptions& options) {
  // Impl::held's positions and normals, appended piece by piece (a vector grows to at most twice its size).
  return meshio::checkWriteTarget(path, options) == ".stl" ? 2 * 2 * sizeof(glm::dvec3) : 0;
}

}  // namespace sffd
