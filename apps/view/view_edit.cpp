// LatticeEdit (view_edit.h): snapshots of the lattice before each step; a redo list cleared by a new step.
#include "apps/view/view_edit.h"

#include <algorithm>
#include <numeric>

namespace sffd::view {

LatticeEdit::LatticeEdit(Lattice lattice, size_t maxUndo)
    : lattice_(std::move(lattice)), original_(lattice_), maxUndo_(std::max<size_t>(maxUndo, 1)) {}

void LatticeEdit::select(std::vector<size_t> points, bool add) {
  if (add) points.insert(points.end(), selection_.begin(), selection_.end());
  points.erase(std::remove_if(points.begin(), points.end(), [&](size_t p) { return p >= lattice_.controlPoints.size(); }),
               points.end());
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  selection_ = std::move(points);
}

void LatticeEdit::selectAll() {
  selection_.resize(lattice_.controlPoints.size());
  std::iota(selection_.begin(), selection_.end(), size_t(0));
}

bool LatticeEdit::selected(size_t point) const { return std::binary_search(selection_.begin(), selection_.end(), point); }

void LatticeEdit::pushUndo() {
  undo_.push_back(lattice_);
  if (undo_.size() > maxUndo_) undo_.erase(undo_.begin());
  redo_.clear();
}

void LatticeEdit::beginGesture() {
  if (inGesture_) return;
  pushUndo();
  inGesture_ = true;
}

void LatticeEdit::endGesture() { inGesture_ = false; }

void LatticeEdit::moveSelected(const glm::dvec3& delta) {
  if (selection_.empty()) return;
  if (!inGesture_) pushUndo();
  for (size_t p : selection_) lattice_.controlPoints[p] += delta;
  ++version_;
}

void LatticeEdit::replace(const Lattice& lattice) {
  inGesture_ = false;
  pushUndo();
  lattice_ = lattice;
  select(selection_);   // drops indices the new lattice lacks
  ++version_;
}

bool LatticeEdit::undo() {
  if (undo_.empty()) return false;
  inGesture_ = false;
  redo_.push_back(std::move(lattice_));
  lattice_ = std::move(undo_.back());
  undo_.pop_back();
  select(selection_);
  ++version_;
  return true;
}

bool LatticeEdit::redo() {
  if (redo_.empty()) return false;
  inGesture_ = false;
  undo_.push_back(std::move(lattice_));
  lattice_ = std::move(redo_.back());
  redo_.pop_back();
  select(selection_);
  ++version_;
  return true;
}

}  // namespace sffd::view
