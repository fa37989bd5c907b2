// Linked instead of transport_endpoint.cpp when the build has no ground-link transport library: the benchmark
// then measures the seed's protocol only and says so.
#include "bench/linkbench/endpoint.hpp"

namespace airseg::linkbench {

std::unique_ptr<BenchEndpoint> make_transport_endpoint(const EndpointSetup& /*setup*/) {
    return nullptr;
}

}  // namespace airseg::linkbench
