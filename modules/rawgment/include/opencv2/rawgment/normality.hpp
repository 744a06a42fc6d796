// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_NORMALITY_HPP
#define OPENCV_RAWGMENT_NORMALITY_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_normality
//! @{

/** @brief Result of a Shapiro-Wilk test of one sample. */
struct CV_EXPORTS_W_SIMPLE ShapiroWilkResult
{
    //! Every field at its default, as initialised here.
    CV_WRAP ShapiroWilkResult() : W(0), pValue(0), n(0), constant(false) {}
    CV_PROP_RW double W;      //!< the W statistic, in [0, 1]; 1 for a sample that lies exactly on a normal
    CV_PROP_RW double pValue; //!< probability of a W this small or smaller if the sample were normal
    CV_PROP_RW int n;         //!< sample size
    CV_PROP_RW bool constant; //!< every value was equal (see shapiroWilk() for what W and pValue are then)
};

/** @brief Shapiro-Wilk test of normality @cite shapiro1965analysis, with Royston's approximation of the
 * coefficients and of the null distribution of W, algorithm AS R94 @cite royston1995remark.
 *
 * This is the algorithm of R's `shapiro.test` and SciPy's `scipy.stats.shapiro`; the tests check
 * \f$ |W - W_R| \le 10^{-7} \f$ and \f$ |p - p_R| \le 10^{-6}\max(p_R, 10^{-10}) + 10^{-12} \f$
 * against R 4.2 on normal, uniform, exponential, log-normal, Student t(3) and integer (tied) samples of
 * sizes 3 to 5000.
 *
 * With the sorted sample \f$ x_{(1)} \le \dots \le x_{(n)} \f$ and the antisymmetric coefficients
 * \f$ a_i \f$ of AS R94,
 * \f[ W = \frac{\left(\sum_i a_i x_{(i)}\right)^2}{\sum_i (x_i - \bar x)^2}, \f]
 * computed as the squared correlation of \f$ a \f$ and \f$ x \f$ and through \f$ 1 - W \f$, which
 * keeps its precision when W is close to 1. For n = 3 the p-value is exact,
 * \f$ p = \frac{6}{\pi}\left(\arcsin\sqrt{W} - \frac{\pi}{3}\right) \f$; for 4 <= n <= 11 and
 * n >= 12, \f$ \log(1 - W) \f$ (after a further transform for small n) is normal with Royston's
 * polynomial mean and standard deviation.
 *
 * The data are centred on their minimum and scaled by their range before the sums, so a sample with a
 * large offset and a small spread (a bright pixel of a burst: mean 60000, variance 1) loses no digits.
 *
 * @param samples the sample: every element of a single-channel Mat of any numeric depth (CV_8U to
 *        CV_64F, any shape), or a std::vector of numbers; 3 <= n <= 5000
 * @return W, p-value and n. A sample whose values are all equal has no spread and cannot come from a
 *         continuous normal distribution: the result has `constant = true`, W = 0 and p = 0 (normality
 *         rejected). R's `shapiro.test` stops with an error instead; returning a flagged rejection lets
 *         a batch over a burst with clipped pixels finish and count those pixels as non-Gaussian, which
 *         they are.
 * @throws cv::Exception (StsBadArg) when n < 3 or n > 5000 (the message gives the valid range), when
 *         a value is NaN or infinite, or when the input has more than one channel.
 */
CV_EXPORTS_W ShapiroWilkResult shapiroWilk(InputArray samples);

/** @brief Where the series of a batch lie in its Mat. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum ShapiroWilkLayout: int
// clang-format on
{
    SW_SERIES_IN_COLUMNS = 0, //!< each column is one series of `rows` values
    SW_SERIES_IN_ROWS = 1     //!< each row is one series of `cols` values
};

/** @brief Shapiro-Wilk test of many series of one length, in parallel, with the coefficients computed
 * once.
 *
 * Each result is bit-identical to shapiroWilk() of the same series, whatever the number of threads.
 * @param series single-channel 2-D Mat of any numeric depth holding the series (see layout)
 * @param results output, one ShapiroWilkResult per series, in column (or row) order
 * @param layout whether the series are the columns or the rows of `series`
 * @throws cv::Exception as shapiroWilk(), naming the first series that holds a NaN or infinite value.
 */
CV_EXPORTS_W void shapiroWilkBatch(InputArray series, CV_OUT std::vector<ShapiroWilkResult>& results,
                                   ShapiroWilkLayout layout = SW_SERIES_IN_COLUMNS);

/** @brief Per-pixel Shapiro-Wilk tests of a burst: the temporal series of each chosen position. */
struct CV_RAWGMENT_EXPORTS BurstNormality
{
    std::vector<Point> positions;           //!< the pixel positions tested
    std::vector<double> mean;               //!< temporal mean of each position (input units)
    std::vector<int> distinctValues;        //!< number of distinct values in each series (ties)
    std::vector<ShapiroWilkResult> results; //!< the test of each position
};

/** @brief Tests, for each position, whether its values over the frames of a burst are Gaussian (paper
 * Sec. 4.3, Fig. "shapiro").
 * @param frames the burst: 3 to 5000 single-channel frames of one size and one type (CV_16UC1,
 *        CV_32FC1, or any numeric depth)
 * @param positions pixel positions to test; empty means every pixel of the frame
 * @throws cv::Exception when the frames differ in size or type, a position is outside the frame, the
 *         number of frames is outside [3, 5000], or a value is NaN or infinite.
 */
CV_RAWGMENT_EXPORTS BurstNormality
shapiroWilkBurst(InputArrayOfArrays frames, const std::vector<Point>& positions = std::vector<Point>());

/** @brief One bin of the mean axis of a burst's normality summary. */
struct CV_RAWGMENT_EXPORTS NormalityBin
{
    double meanLow = 0;            //!< lower edge of the bin (inclusive)
    double meanHigh = 0;           //!< upper edge of the bin (exclusive, inclusive for the last bin)
    int count = 0;                 //!< positions whose mean falls in the bin
    double fractionAboveAlpha = 0; //!< fraction of them with p-value > alpha (not rejected)
    double medianPValue = 0;       //!< median p-value of the bin
    double meanDistinctValues = 0; //!< average number of distinct values per series: few means many ties
};

/** @brief The fraction of Gaussian-looking pixels against their mean, in bins of the mean.
 *
 * At very low means the values of a series are a handful of integers; the ties make W small and the
 * test rejects normality although the underlying noise is close to Gaussian. `meanDistinctValues`
 * shows that cause next to the rejection rate.
 * @param burst the result of shapiroWilkBurst()
 * @param bins number of bins (>= 1), spaced evenly between the smallest and the largest mean
 * @param alpha significance level in (0, 1), 0.05 in the paper
 * @return the bins, empty ones included (count 0, other fields 0)
 */
CV_RAWGMENT_EXPORTS std::vector<NormalityBin> summarizeNormality(const BurstNormality& burst, int bins,
                                                                 double alpha = 0.05);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_NORMALITY_HPP
