// pmr bench --queue-stats: what the last frame's work was made of (docs/PERFORMANCE.md, "Where a
// frame's work goes"), read back from the pipeline: the multi-view triangles (MTAs), their tile-queue
// entries, and their footprints, as histograms, with the stage times per unit of work.
#pragma once
#include "pipeline/pipeline.h"

namespace pmr {

// Prints the histograms of the pipeline's last frame (tile queues, MTAs) to stdout as '#' lines, and
// the frame's stage times (`t`) per MTA, per queue entry and per footprint pixel.
void print_queue_stats(const Pipeline& pipeline, const StageTimes& t);

}  // namespace pmr
