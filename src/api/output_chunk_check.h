// What the interop headers' bufferOf (vulkan_interop.cpp, opengl_interop.cpp) check before they look a
// chunk's buffer up, so that their errors say which of the caller's mistakes it is.
#pragma once
#include <string>

#include <sffd/deformer.h>
#include <sffd/error.h>

namespace sffd {

// An input Error from `call` unless the Deformer's device is one of `api` (onApi) and `chunk` is one of
// those its deviceOutput() gives now.
inline void checkOutputChunk(const Deformer& deformer, const OutputChunk& chunk, const char* call, bool onApi, const char* api) {
  const Device& device = deformer.device();
  if (!onApi)
    throw Error(ErrorKind::Input, std::string(call) + ": the Deformer runs on " + device.label() + " (" + device.info().api +
                                      "), not on a " + api + " device");
  const std::vector<OutputChunk> out = deformer.deviceOutput();
  for (const OutputChunk& c : out)
    if (c.first == chunk.first && c.count == chunk.count && c.buffer == chunk.buffer && c.offset == chunk.offset && c.bytes == chunk.bytes)
      return;
  const std::string which = "the chunk (buffer " + std::to_string(chunk.buffer) + ", bytes " + std::to_string(chunk.offset) + "+" +
                            std::to_string(chunk.bytes) + ") is not one of the Deformer's deviceOutput()";
  throw Error(ErrorKind::Input, std::string(call) + ": " + which +
                                    (out.empty() ? ", which is empty (before a deform() has succeeded, or on a device or one-shot "
                                                   "Deformer that keeps no output)"
                                                 : ", " + std::to_string(out.size()) + " chunks"));
}

}  // namespace sffd
