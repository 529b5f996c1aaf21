#include "deform_job.h"
#include "error.h"

namespace sffd::cli {

DeformRun runAccurate(const ParsedArgs&, Job&, OpenedBackend&) {
  throw Error(ErrorKind::Internal, "--method accurate is not available in this build yet");
}

}  // namespace sffd::cli
