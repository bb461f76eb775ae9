// A named stage of the wavefront: executors time every launch under its stage's
// name and index, and name the stage in errors.
#pragma once

namespace wt {

struct Stage {
  int index;
  const char* name;
};

}  // namespace wt
