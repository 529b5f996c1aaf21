#include "deform_job.h"
#include "error.h"

namespace sffd::cli {

DeformRun runSmooth(const ParsedArgs&, Job&, OpenedBackend&) {
  throw Error(ErrorKind::Internal, "--method smooth is not available in this build yet; use --method classic");
}

}  // namespace sffd::cli
