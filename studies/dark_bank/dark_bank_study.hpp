// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank against independent captures on simulated sensors that depart from the parametric
// components (hot pixels, noisy pixels, column banding), side by side with the calibrated components and the
// plain Gaussian (docs/dark_frame_bank.md): study_dark_bank prints its table, the test holds it.
#ifndef RAWGMENT_STUDIES_DARK_BANK_STUDY_HPP
#define RAWGMENT_STUDIES_DARK_BANK_STUDY_HPP

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rawgment_studies {

/** One study: campaigns of a sensor, each with its own fixed pattern, bank, inputs and targets. */
struct DarkBankStudySettings
{
    cv::Size size{128, 96};
    int bankFrames = 25;    //!< dark frames per gain in each campaign's bank (not the targets)
    int outputs = 32;       //!< augmented outputs of each method, and independent target captures
    int campaigns = 8;      //!< each with a new sensor (fixed pattern), bank, inputs and targets
    double gainIn = 1;      //!< the inputs' gain
    double gainOut = 8;     //!< the targets'
    double contrast = 0.25; //!< k: the step scales the input's values (and its read noise) by it
    int bootstrap = 100;    //!< resamplings of frames for each KS statistic's null
    std::string workDir;    //!< where each campaign's bank is written (a folder per campaign)
};

/** A method's figures over the campaigns: each the mean of (method - target) with its standard error over
 * campaigns, except the target's own row, which holds the target's values. */
struct DarkBankMethod
{
    std::string name;
    double rowPart = 0, rowPartSe = 0;       //!< variance of a row's mean over frames (DN^2)
    double columnPart = 0, columnPartSe = 0; //!< variance of a column's mean over frames (DN^2)
    double pixelPart = 0, pixelPartSe = 0;   //!< a pixel's variance about its row's mean (DN^2)
    double fpnRms = 0, fpnRmsSe = 0; //!< fixed-pattern RMS: sqrt(Var(mean of N) - v/N), hot pixels out (DN)
    double hotError = 0,
           hotErrorSe = 0; //!< the hot pixels' mean level: its RMS error (the target: the level)
    double kurtosis = 0, kurtosisSe = 0; //!< the pixel part's excess kurtosis
    //! what the kurtosis should be for the mixture the method adds (NaN: not derived), as a difference too
    double expectedKurtosis = 0, expectedKurtosisSe = 0;
    double ks = 0;      //!< the mean two-sample KS statistic of the pixel parts against the target's
    int ksRejected = 0; //!< campaigns where the bootstrap over frames rejects at 5%
};

struct DarkBankStudy
{
    DarkBankMethod target;
    std::vector<DarkBankMethod> methods; //!< bank accounted, bank ignoring the prior, components, Gaussian
    int campaigns = 0;
};

//! Runs the study (deterministic: the same settings give the same numbers).
DarkBankStudy runDarkBankStudy(const DarkBankStudySettings& settings);

//! The study as a Markdown table with its settings.
std::string darkBankStudyMarkdown(const DarkBankStudy& study, const DarkBankStudySettings& settings);

/** E[excess kurtosis of x - mean of n] / (excess kurtosis of x): residuals about a pixel's own mean over n
 * frames mix in 1/n of the others, which pulls their shape towards the Gaussian. */
double residualKurtosisFactor(int n);

//! The two-sample Kolmogorov-Smirnov statistic of a and b (ties handled as one step).
double ksStatistic(std::vector<float> a, std::vector<float> b);

/** One figure of a method on the real sensor against what the real frames show: the method's value, the real
 * one, and the standard error of their difference. */
struct RealComparison
{
    std::string part;    //!< "half against half" or the darkened step ("step 21 to 6, photon ratio 0.25")
    std::string method;  //!< the bank (accounted, untied), the bank ignoring the prior, components, Gaussian
    std::string measure; //!< what is compared, with its unit
    double value = 0, real = 0, se = 0;
    //! The difference is beyond 3 standard errors: the method is told apart from the real frames.
    bool distinguishable() const;
};

/** The dark-frame bank on a real sensor: EMVA 1288 reference set 001 (one gain, 50 exposures; docs/
 * dark_frame_bank.md, "A real sensor"). */
struct Emva1288BankStudy
{
    std::vector<RealComparison> rows;
    //! The first half's fixed pattern, Var(mean) - v/M per site: the bank's own figure and the study's
    //! arithmetic
    double bankFixedPattern = 0, studyFixedPattern = 0;
    std::vector<std::string> notes; //!< what the reader needs to read the rows (settings, halves, exposures)
};

/** Runs the real-sensor study on an EMVA 1288 descriptor with a spatial set of dark frames: banks of the
 * first and last halves of the spatial darks (written as PNG mosaics with sidecars under workDir), the half
 * against half comparison of each method's read-noise figures, and bright steps darkened to darker ones with
 * each method against the darker steps' real pairs, each augmented pair drawn `draws` times. */
Emva1288BankStudy runEmva1288BankStudy(const std::string& descriptor, const std::string& workDir,
                                       int draws = 8);

//! The real-sensor study as a Markdown table.
std::string emva1288BankStudyMarkdown(const Emva1288BankStudy& study);

} // namespace rawgment_studies

#endif // RAWGMENT_STUDIES_DARK_BANK_STUDY_HPP
