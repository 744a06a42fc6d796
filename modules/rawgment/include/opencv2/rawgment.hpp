// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_HPP
#define OPENCV_RAWGMENT_HPP

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/camera_profiles.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/emva1288.hpp>
#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/isp.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/normality.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/seeds.hpp>
#include <opencv2/rawgment/simulate.hpp>

/** @defgroup rawgment Noise-accounted RAW augmentation

Makes RAW images of hard scenes (dark, noisy, blurred) out of RAW images of easy ones, with the noise a
real sensor would have produced @cite yoshimura2023rawgment. All values are in DN after black-level
subtraction; gains are linear (0 dB = 1).

@{
    @defgroup rawgment_augment Noise-accounted augmentation: colour jitter, blur, scenes, random policy
    @defgroup rawgment_bayer Bayer mosaics: CFA patterns, planes and black levels
    @defgroup rawgment_noise_model The heteroscedastic Gaussian noise model
    @defgroup rawgment_normality Shapiro-Wilk tests of the Gaussian noise assumption
    @defgroup rawgment_isp The paper's simple ISPs: tone curves, white balance, demosaicing for previews
    @defgroup rawgment_raw_io Camera RAW files in (LibRaw) and out (DNG), and the noise profiles of other
tools
    @defgroup rawgment_mosaic_files Mosaics with YAML sidecars (PNG, TIFF, DNG): what augmentation writes and
reads
    @defgroup rawgment_files Files of every topic: atomic writes, bounded reads, guarded YAML/JSON
    @defgroup rawgment_emva1288 EMVA 1288 series: the standard's descriptor, figures and calibration
    @defgroup rawgment_dark_frames Real dark frames as the read noise: a bank per gain and exposure
    @defgroup rawgment_calibration Noise calibration from bursts: statistics, line fits, cross-gain fits
    @defgroup rawgment_cpu Instruction-set paths of the hot loops: one binary, the same bits on every CPU
    @defgroup rawgment_simulate A physical sensor simulator and a ColorChecker scene: the ground truth
    @defgroup rawgment_seeds Seeds: one user seed, an independent stream for every use of it
@}
*/

#endif // OPENCV_RAWGMENT_HPP
