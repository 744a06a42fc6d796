// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_augment: N variants of each input under a scene or a random policy.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

AugmentResult augmentFiles(const AugmentOptions& o)
{
    const AugmentRecipe recipe = loadAugmentRecipe(o);
    const AugmentPlan plan = planAugmentJobs(o);
    AugmentResult result;
    result.outputs = plan.outputs;
    result.skipped = plan.skipped;
    ProgressBar progress("augment", plan.jobs.size());
    std::mutex errorMutex;
    std::string firstError;
    std::atomic<int> written{0};
    cv::parallel_for_(cv::Range(0, int(plan.jobs.size())), [&](const cv::Range& range) {
        for (int j = range.start; j < range.end; ++j) {
            const AugmentJob& job = plan.jobs[size_t(j)];
            try {
                runAugmentJob(job, recipe);
                ++written;
            } catch (const std::exception& e) {
                std::lock_guard<std::mutex> lock(errorMutex);
                if (firstError.empty())
                    firstError =
                        "'" + job.input + "' variant " + std::to_string(job.variant) + ": " + e.what();
            }
            progress.advance();
        }
    });
    progress.finish();
    result.written = written;
    if (!firstError.empty())
        throw std::runtime_error(firstError);
    return result;
}

} // namespace rawgment_apps
