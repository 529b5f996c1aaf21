// A context provider's library opened at run time (no provider links one: gl_context.h) and its entry
// points. It stays open for the life of the process: unloading Mesa is never safe.
#pragma once
#include <dlfcn.h>

#include <initializer_list>
#include <string>
#include <type_traits>

namespace sffd::gl {

struct RuntimeLibrary {
  void* handle = nullptr;   // null when the library, or one of its required entry points, is missing
  std::string loadError;    // the first thing missing

  // Opens the first of `names` that loads; `label` names the library in loadError ("libEGL").
  RuntimeLibrary(const char* label, std::initializer_list<const char*> names) : label_(label) {
    for (const char* name : names) {
      handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (handle) {
        loadError.clear();   // an earlier name's failure
        return;
      }
      const char* e = dlerror();
      if (loadError.empty()) loadError = e ? e : name;
    }
  }
  // Resolves an entry point the provider cannot work without.
  template <class Fn>
  void require(Fn& fn, const char* name) {
    if (!handle) return;
    fn = reinterpret_cast<std::remove_reference_t<Fn>>(dlsym(handle, name));
    if (!fn && loadError.empty()) loadError = std::string(label_) + " has no " + name;
  }
  // After the required entry points: whether the library is usable (handle cleared when one was missing).
  bool finishRequired() {
    if (!loadError.empty()) handle = nullptr;
    return handle != nullptr;
  }
  bool ok() const { return handle != nullptr; }

 private:
  const char* label_;
};

}  // namespace sffd::gl
