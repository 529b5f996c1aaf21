#include <sffd/sffd.h>

namespace sffd {

#define SFFD_STRINGIFY_(x) #x
#define SFFD_STRINGIFY(x) SFFD_STRINGIFY_(x)

const char* version() {
  return SFFD_STRINGIFY(SFFD_VERSION_MAJOR) "." SFFD_STRINGIFY(SFFD_VERSION_MINOR) "." SFFD_STRINGIFY(SFFD_VERSION_PATCH);
}

}  // namespace sffd
