// Every kernel of cmake/Kernels.cmake with its CPU entry (backend_contract_test.cc checks that none is missing).
#include <iterator>

#include "backends/cpu/cpu_backend.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/classic/classic_ffd.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/pn/pn_triangles.h"
#include "kernels/smooth/smooth_deform.h"

namespace sffd::cpu {

const Kernel* findKernel(std::string_view name) {
  static const Kernel kTable[] = {
      {"classic_ffd", sizeof(gpu::ClassicParams), cpu::classicFfd},
      {"pn_triangles", sizeof(gpu::PnParams), cpu::pnTriangles},
      {"clip_count", sizeof(gpu::ClipParams), cpu::clipCount},
      {"clip_write", sizeof(gpu::ClipParams), cpu::clipWrite},
      {"deform_smooth", sizeof(gpu::DeformParams), cpu::deformSmooth},
      {"deform_step_sample", sizeof(gpu::DeformParams), cpu::deformStepSample},
      {"deform_step_fit", sizeof(gpu::DeformParams), cpu::deformStepFit},
      {"deform_step_adjust", sizeof(gpu::DeformParams), cpu::deformStepAdjust},
      {"deform_step_tessellate", sizeof(gpu::DeformParams), cpu::deformStepTessellate},
      {"accurate_patches", sizeof(gpu::AccurateParams), cpu::accuratePatches},
  };
  for (const Kernel& k : kTable)
    if (name == k.name) return &k;
  return nullptr;
}

}  // namespace sffd::cpu
