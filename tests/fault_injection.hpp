// Test-only device faults: nothing in the program's own code paths knows of them.
#pragma once

namespace wt::test {

// Launches the tests' own kernel, which stores through a null pointer, and waits for
// it: throws cuda::CudaError "fault test: cudaDeviceSynchronize() failed:
// cudaErrorIllegalAddress (...)" and leaves the context poisoned (a sticky error), as
// a faulting render kernel would. Needs a device.
void poison_device();

}  // namespace wt::test
