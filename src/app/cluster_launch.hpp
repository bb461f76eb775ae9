// How this process was started: what start_cluster reads from the environment.
#pragma once

namespace wt::app {

// The ranks the launcher started (1 where none, or where kSingleProcessVariable is
// set; 0 where a launcher started this process without saying how many).
int launched_ranks();

}  // namespace wt::app
