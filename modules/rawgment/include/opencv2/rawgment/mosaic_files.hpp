// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_MOSAIC_FILES_HPP
#define OPENCV_RAWGMENT_MOSAIC_FILES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/raw_io.hpp>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_mosaic_files
//! @{

/** @brief What a sidecar file says about a mosaic written by writeMosaic(). */
struct CV_RAWGMENT_EXPORTS MosaicMetadata
{
    /** Version written to files whose format states an exposure time without camera tags (with tags, the
     * tags carry it); 4 to files that set gainFromIso; 3 otherwise, so that their bytes stay as they were.
     * Versions 1 (no camera tags), 2 (no noise camera), 3, 4 and 5 are read; the format read takes the
     * camera tags' exposure time when it states none. */
    static constexpr int FORMAT_VERSION = 5;
    RawFormat format;       //!< the mosaic's format, with the gain after augmentation
    bool hasScene = false;  //!< whether `scene` and `seed` describe how the mosaic was made
    Scene scene;            //!< the scene applied to the source
    uint64 seed = 0;        //!< the noise seed of that scene
    String source;          //!< the file the mosaic was made from (informative)
    bool hasCamera = false; //!< whether `camera` describes the mosaic (a DNG then carries the tags)
    CameraTags camera;      //!< the camera and capture, when hasCamera
    /** The real camera whose measured noise the scene simulated (a darktable profile's "maker model",
     * CameraNoiseProfile::name()); empty when the noise model came from elsewhere. */
    String noiseCamera;
    /** The mosaic is a camera file's raw as LibRaw reads it (gain 1), converted (rawgment_convert): its
     * gain is the ISO of `camera` over a noise model's base ISO, as for the camera file itself. Needs
     * camera tags with an ISO and format.gain 1. */
    bool gainFromIso = false;
    Size size;           //!< the mosaic's size; set by writeMosaic(), checked by readMosaic()
    int type = CV_16UC1; //!< the mosaic's type; set by writeMosaic(), checked by readMosaic()

    /** @brief The format to augment the mosaic with `model`: formatAtIso() at the camera's ISO when
     * gainFromIso, else `format` as it is. @throws cv::Exception as formatAtIso(). */
    RawFormat formatFor(const NoiseModel& model) const;
    //! Writes the metadata as a map under `name`.
    void write(FileStorage& fs, const String& name) const;
    //! Reads metadata written by write(). @throws cv::Exception naming an invalid field.
    static MosaicMetadata read(const FileNode& node);
};

/** @brief A file container of mosaics: its extensions and what the library does with it.
 *
 * mosaicContainers() is the one table of them: writeMosaic() and readMosaic() decide by it, and the apps, the
 * pipeline and the Python package take their lists of extensions from it. */
struct CV_RAWGMENT_EXPORTS MosaicContainer
{
    String name;                    //!< the container's name, its first extension without the dot ("tif")
    std::vector<String> extensions; //!< lower case, with the dot; the first is the one an app writes
    bool readsMosaic = false;       //!< readMosaic() reads it beside its sidecar
    bool writes = false;            //!< writeMosaic() writes it
    bool float32 = false;           //!< holds CV_32FC1 mosaics as well as CV_16UC1
    bool cameraRaw = false;         //!< a camera's own file, read by readRaw() (LibRaw) with no sidecar
};

/** @brief Every container of mosaics: DNG, numpy's `.npy`, PNG, TIFF, and the camera RAW formats LibRaw
 * reads.
 */
CV_RAWGMENT_EXPORTS const std::vector<MosaicContainer>& mosaicContainers();

/** @brief The container of a path by its extension (any case); null when no container has it. */
CV_RAWGMENT_EXPORTS const MosaicContainer* mosaicContainerOf(const String& path);

/** @brief The sidecar of a mosaic file: `path` + ".yml". */
CV_RAWGMENT_EXPORTS String sidecarPathOf(const String& path);

/** @brief Writes a mosaic and its sidecar YAML (top-level map `mosaic_metadata`).
 *
 * The container follows the extension: `.png` (16-bit), `.tif`/`.tiff` (16-bit or 32-bit float,
 * uncompressed), `.dng` (16-bit, see writeDng()) or `.npy` (16-bit or 32-bit float: numpy's format,
 * uncompressed and C-ordered, the one to train from: readMosaic() reads it at the speed of a copy from
 * the page cache, and numpy maps it without a copy, `np.load(path, mmap_mode="r")`). The sidecar is written
 * first and the image last, each atomically, and neither replaces an existing file: an existing image marks a
 * finished output, and an input can never be overwritten. An existing sidecar without its image is kept when
 * it holds exactly the text this call would write (an interrupted run of the same job) and is an error
 * otherwise; an existing image and sidecar that hold exactly these bytes (another writer of the same job,
 * such as a second run into the same folder at the same time) are this call's output, and any other existing
 * image is an error. When the image cannot be written, the sidecar this call wrote is removed unless an image
 * another writer made meanwhile depends on it: no sidecar is left without its image.
 * @param path destination image, which must not exist
 * @param mosaic CV_16UC1 (any container) or CV_32FC1 (TIFF and .npy)
 * @param metadata the format, and optionally the scene and seed that made the mosaic and the camera tags
 *        (validated); a DNG carries the camera tags when `hasCamera`
 * @throws cv::Exception when `path` exists, the type does not fit the container, the camera tags do not
 *         fit a DNG (see writeDng()), or a write fails.
 */
CV_RAWGMENT_EXPORTS void writeMosaic(const String& path, InputArray mosaic, const MosaicMetadata& metadata);

/** @brief Reads a mosaic written by writeMosaic() and its sidecar.
 * @param path the image; its sidecar must be beside it
 * @param mosaic output, the stored type
 * @return the sidecar's metadata
 * @throws cv::Exception naming the file when either is missing or invalid, or when the image's size or
 *         type contradicts the sidecar.
 */
CV_RAWGMENT_EXPORTS MosaicMetadata readMosaic(const String& path, OutputArray mosaic);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_MOSAIC_FILES_HPP
