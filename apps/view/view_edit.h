// The lattice being edited in `sffd view`: control-point moves, the selection, and an undo/redo
// history of whole control-point snapshots (exact: undo gives back the very same doubles). No GL.
#pragma once
#include <cstddef>
#include <vector>

#include "model/lattice.h"

namespace sffd::view {

class LatticeEdit {
 public:
  explicit LatticeEdit(Lattice lattice, size_t maxUndo = 512);

  const Lattice& lattice() const { return lattice_; }
  const Lattice& original() const { return original_; }
  // Bumped on every change of the control points (moves, undo, redo, load).
  size_t version() const { return version_; }

  // Selection: indices into lattice().controlPoints, sorted, unique.
  const std::vector<size_t>& selection() const { return selection_; }
  void select(std::vector<size_t> points, bool add = false);
  void selectAll();
  void clearSelection() { selection_.clear(); }
  bool selected(size_t point) const;

  // A gesture (one mouse drag, one script `drag`) is one undo step however many moves it makes.
  void beginGesture();
  void endGesture();
  bool inGesture() const { return inGesture_; }
  // Moves the selected points by `delta` (model units). Outside a gesture it is a step of its own.
  void moveSelected(const glm::dvec3& delta);

  // Replaces the whole lattice (load, reset) as one undo step. The structure may differ.
  void replace(const Lattice& lattice);

  bool canUndo() const { return !undo_.empty(); }
  bool canRedo() const { return !redo_.empty(); }
  bool undo();
  bool redo();

 private:
  void pushUndo();
  Lattice lattice_, original_;
  std::vector<size_t> selection_;
  std::vector<Lattice> undo_, redo_;
  size_t maxUndo_;
  size_t version_ = 0;
  bool inGesture_ = false;
};

}  // namespace sffd::view
