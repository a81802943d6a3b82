#pragma once

#include <facet/fwd.h>
#include <facet/image.h>

#include <atomic>
#include <cstdint>
#include <string>

namespace facet {

struct RenderOptions {
    int threads = 0;   ///< 0 = all cores
    uint64_t seed = 0; ///< added to the sampler's seed
    int spp = 0;       ///< 0 = the sampler's sample_count
    int block_size = 32;
    bool progress = true; ///< progress line on a terminal (never when stderr is not a tty)
    /// Set to true (e.g. by a signal handler) to stop after the blocks in flight.
    std::atomic<bool> *cancel = nullptr;
};

struct RenderResult {
    Image image; ///< developed film (crop window), plus AOV channels
    double seconds = 0.0;
    bool cancelled = false;
    size_t blocks_done = 0, blocks_total = 0;
    uint64_t samples = 0; ///< camera samples taken
};

/// Renders `sensor` of `scene` with the scene's integrator (a SamplingIntegrator) block by block
/// on TBB threads. Deterministic: the same scene, seed and spp give the same image for any
/// thread count.
RenderResult render(const Scene &scene, const Sensor &sensor, const RenderOptions &opts);

/// Installs SIGINT/SIGHUP handlers that set `flag` (restored by uninstall_interrupt_handler).
void install_interrupt_handler(std::atomic<bool> *flag);
void uninstall_interrupt_handler();

} // namespace facet
