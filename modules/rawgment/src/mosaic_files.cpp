// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The mosaic_files topic (mosaic_files.hpp): mosaics written with a YAML sidecar of their format, scene,
// seed and camera tags, and read back with every field checked against the image.
#include "image_headers.hpp"
#include "raw_io_detail.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>

#include <algorithm>
#include <cstdio>
#include <vector>

namespace cv {
namespace rawgment {

RawFormat MosaicMetadata::formatFor(const NoiseModel& model) const
{
    return gainFromIso ? formatAtIso(format, camera.iso, model) : format;
}

void MosaicMetadata::write(FileStorage& fs, const String& name) const
{
    format.validate();
    if (gainFromIso && !(hasCamera && camera.iso > 0 && format.gain == 1))
        CV_Error(Error::StsBadArg,
                 "mosaic metadata: gainFromIso needs camera tags with an ISO and a gain of 1");
    // The camera tags carry the exposure time when there are tags: one capture has one.
    if (hasCamera && format.exposureTime > 0 && camera.exposureTime > 0 &&
        std::abs(format.exposureTime - camera.exposureTime) > 1e-9 * camera.exposureTime)
        CV_Error(
            Error::StsBadArg,
            cv::format("mosaic metadata: the format's exposure time %g s differs from the camera tags' %g "
                       "s",
                       format.exposureTime, camera.exposureTime));
    RawFormat written = format;
    CameraTags tags = camera;
    if (hasCamera) {
        tags.exposureTime = camera.exposureTime > 0 ? camera.exposureTime : format.exposureTime;
        written.exposureTime = 0;
    }
    fs << name << "{";
    // Versions 4 and 5 only where their one addition each is used, so that every other sidecar stays
    // readable by older releases and its bytes stay what they were.
    fs << "format_version" << (written.exposureTime > 0 ? FORMAT_VERSION : gainFromIso ? 4 : 3);
    written.write(fs, "raw_format");
    fs << "size" << size;
    fs << "type" << typeToString(type);
    writeString(fs, "source", source);
    fs << "has_scene" << int(hasScene);
    if (hasScene) {
        scene.write(fs, "scene");
        // FileStorage has no 64-bit integer: the seed travels as a decimal string.
        fs << "seed" << cv::format("%llu", static_cast<unsigned long long>(seed));
    }
    if (hasCamera)
        tags.write(fs, "camera");
    if (!noiseCamera.empty())
        writeString(fs, "noise_camera", noiseCamera);
    if (gainFromIso)
        fs << "gain_from_iso" << 1;
    fs << "}";
}

MosaicMetadata MosaicMetadata::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "mosaic metadata: expected a map with format_version and raw_format");
    const FileNode version = node["format_version"];
    if (version.empty() || !version.isInt() || int(version) < 1 || int(version) > FORMAT_VERSION)
        CV_Error(
            Error::StsParseError,
            cv::format("mosaic metadata: format_version is missing or not one of 1..%d", FORMAT_VERSION));
    try {
        rejectUnknownKeys(node, {"format_version", "raw_format", "size", "type", "source", "has_scene",
                                 "scene", "seed", "camera", "noise_camera", "gain_from_iso"});
    } catch (const Exception& e) {
        CV_Error(e.code, "mosaic metadata: " + e.err);
    }
    MosaicMetadata m;
    m.format = RawFormat::read(node["raw_format"]);
    node["size"] >> m.size;
    const String typeName = node["type"].empty() ? String() : String(node["type"]);
    if (typeName == "CV_16UC1")
        m.type = CV_16UC1;
    else if (typeName == "CV_32FC1")
        m.type = CV_32FC1;
    else
        CV_Error(Error::StsParseError,
                 "mosaic metadata: field 'type' must be CV_16UC1 or CV_32FC1 (got '" + typeName + "')");
    if (m.size.width <= 0 || m.size.height <= 0)
        CV_Error(Error::StsParseError, "mosaic metadata: field 'size' is missing or not positive");
    m.source = node["source"].empty() ? String() : String(node["source"]);
    m.hasScene = !node["has_scene"].empty() && int(node["has_scene"]) != 0;
    if (m.hasScene) {
        m.scene = Scene::read(node["scene"]);
        const String seed = node["seed"].empty() ? String() : String(node["seed"]);
        char* end = nullptr;
        errno = 0;
        const unsigned long long v = std::strtoull(seed.c_str(), &end, 10);
        if (seed.empty() || *end != '\0' || errno != 0)
            CV_Error(Error::StsParseError,
                     "mosaic metadata: field 'seed' is missing or not a decimal integer");
        m.seed = static_cast<uint64>(v);
    }
    const FileNode noiseCamera = node["noise_camera"];
    if (!noiseCamera.empty() && !noiseCamera.isString())
        CV_Error(Error::StsParseError, "mosaic metadata: field 'noise_camera' must be a string");
    m.noiseCamera = noiseCamera.empty() ? String() : String(noiseCamera);
    m.hasCamera = !node["camera"].empty();
    if (m.hasCamera) {
        m.camera = CameraTags::read(node["camera"]);
        if (m.format.exposureTime == 0)
            m.format.exposureTime = m.camera.exposureTime;
    }
    const FileNode gainFromIso = node["gain_from_iso"];
    if (!gainFromIso.empty()) {
        try {
            m.gainFromIso = detail::readOptionalFlagField(node, "gain_from_iso", false);
        } catch (const Exception& e) {
            CV_Error(e.code, "mosaic metadata: " + e.err);
        }
        if (m.gainFromIso && !(m.hasCamera && m.camera.iso > 0 && m.format.gain == 1))
            CV_Error(
                Error::StsParseError,
                "mosaic metadata: gain_from_iso needs camera tags with an ISO and a raw_format gain of 1");
    }
    return m;
}

String sidecarPathOf(const String& path)
{
    return path + ".yml";
}
using detail::lowerExtensionOf;

namespace {

std::vector<uchar> dngBytes(const String& path, const String&, const Mat& mosaic, const MosaicMetadata& meta)
{
    RawImage image;
    image.mosaic = mosaic;
    image.format = meta.format;
    if (meta.hasCamera)
        meta.camera.applyTo(image);
    return detail::dngFileBytes(path, image);
}

std::vector<uchar> npyBytes(const String&, const String&, const Mat& mosaic, const MosaicMetadata&)
{
    return detail::npyFileBytes(mosaic);
}

// PNG, or TIFF uncompressed, through OpenCV's encoders.
std::vector<uchar> imageBytes(const String& path, const String& ext, const Mat& mosaic, const MosaicMetadata&)
{
    std::vector<uchar> bytes;
    const std::vector<int> params =
        ext == ".png" ? std::vector<int>{} : std::vector<int>{IMWRITE_TIFF_COMPRESSION, 1};
    bool encoded = false;
    try {
        encoded = imencode(ext, mosaic, bytes, params);
    } catch (const Exception& e) {
        CV_Error(Error::StsError, "writeMosaic: '" + path + "': encoding failed: " + e.err);
    }
    if (!encoded)
        CV_Error(Error::StsError,
                 "writeMosaic: '" + path + "': OpenCV could not encode the mosaic as " + ext);
    return bytes;
}

// A DNG states its own levels and pattern: a sidecar that contradicts them describes another file.
Mat dngMosaic(const String& path, const MosaicMetadata& meta)
{
    const RawImage raw = readRaw(path);
    const RawFormat& f = raw.format;
    if (f.pattern != meta.format.pattern || f.blackLevel != meta.format.blackLevel ||
        f.whiteLevel != meta.format.whiteLevel)
        CV_Error(
            Error::StsError,
            cv::format("readMosaic: '%s' is %s with black %g %g %g %g and white %g, but its sidecar says "
                       "%s with black %g %g %g %g and white %g",
                       path.c_str(), cfaPatternName(f.pattern).c_str(), f.blackLevel[0], f.blackLevel[1],
                       f.blackLevel[2], f.blackLevel[3], f.whiteLevel,
                       cfaPatternName(meta.format.pattern).c_str(), meta.format.blackLevel[0],
                       meta.format.blackLevel[1], meta.format.blackLevel[2], meta.format.blackLevel[3],
                       meta.format.whiteLevel));
    return raw.mosaic;
}

Mat npyMosaic(const String& path, const MosaicMetadata&)
{
    return detail::readNpyMosaic(path);
}

// The header is held to the sidecar before any decode (round 5 item 20: a PNG claiming another size was
// decoded first).
Mat imageMosaic(const String& path, const MosaicMetadata& meta)
{
    try {
        return detail::readImageFileOfSize(path, meta.size, meta.type, "readMosaic: mosaic");
    } catch (const Exception& e) {
        CV_Error(Error::StsError, e.err + " (its sidecar says " +
                                      cv::format("%dx%d %s)", meta.size.width, meta.size.height,
                                                 typeToString(meta.type).c_str()));
    }
}

/* The one table of containers: what each is (MosaicContainer) and how it is written and read. Adding a
 * container is one entry here; MosaicFiles.mosaicRoundTripsWithItsSidecarInEveryContainer writes and reads
 * every entry. */
struct ContainerCodec
{
    MosaicContainer container;
    std::vector<uchar> (*encode)(const String& path, const String& ext, const Mat& mosaic,
                                 const MosaicMetadata& meta);
    Mat (*decode)(const String& path, const MosaicMetadata& meta);
};

const std::vector<ContainerCodec>& codecs()
{
    static const std::vector<ContainerCodec> table = {
        {{"dng", {".dng"}, true, true, false, true}, dngBytes, dngMosaic},
        {{"npy", {".npy"}, true, true, true, false}, npyBytes, npyMosaic},
        {{"png", {".png"}, true, true, false, false}, imageBytes, imageMosaic},
        {{"tif", {".tif", ".tiff"}, true, true, true, false}, imageBytes, imageMosaic},
        // LibRaw's camera formats besides DNG, for picking a camera's files from a folder.
        {{"camera RAW",
          {".nef", ".cr2", ".cr3", ".crw", ".arw", ".raf", ".rw2", ".orf", ".pef", ".kdc", ".srw", ".3fr",
           ".iiq", ".erf", ".mef", ".mos", ".nrw", ".x3f"},
          false,
          false,
          false,
          true},
         nullptr,
         nullptr},
    };
    return table;
}

const ContainerCodec* codecOf(const String& path)
{
    const String ext = lowerExtensionOf(path);
    for (const ContainerCodec& c : codecs())
        if (std::find(c.container.extensions.begin(), c.container.extensions.end(), ext) !=
            c.container.extensions.end())
            return &c;
    return nullptr;
}

//! The extensions of the containers that `has`, as "a, b or c".
String extensionsWhere(bool (*has)(const MosaicContainer&))
{
    std::vector<String> all;
    for (const ContainerCodec& c : codecs())
        if (has(c.container))
            all.insert(all.end(), c.container.extensions.begin(), c.container.extensions.end());
    String text;
    for (size_t i = 0; i < all.size(); ++i)
        text += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + all[i];
    return text;
}

} // namespace

const std::vector<MosaicContainer>& mosaicContainers()
{
    static const std::vector<MosaicContainer> containers = [] {
        std::vector<MosaicContainer> out;
        for (const ContainerCodec& c : codecs())
            out.push_back(c.container);
        return out;
    }();
    return containers;
}

const MosaicContainer* mosaicContainerOf(const String& path)
{
    const ContainerCodec* codec = codecOf(path);
    return codec ? &mosaicContainers()[static_cast<size_t>(codec - codecs().data())] : nullptr;
}

void writeMosaic(const String& path, InputArray _mosaic, const MosaicMetadata& metadata)
{
    const Mat mosaic = detail::twoDimensional(_mosaic, "writeMosaic: mosaic");
    const String ext = lowerExtensionOf(path);
    const ContainerCodec* codec = codecOf(path);
    if (!codec || !codec->container.writes)
        CV_Error(Error::StsBadArg, "writeMosaic: '" + path + "': unsupported extension; expected " +
                                       extensionsWhere([](const MosaicContainer& c) { return c.writes; }));
    const bool takesFloat = codec->container.float32;
    if (mosaic.empty() || (mosaic.type() != CV_16UC1 && !(takesFloat && mosaic.type() == CV_32FC1)))
        CV_Error(Error::StsBadArg,
                 cv::format("writeMosaic: '%s': a %s mosaic cannot be stored as %s; expected CV_16UC1%s",
                            path.c_str(), mosaic.empty() ? "empty" : typeToString(mosaic.type()).c_str(),
                            ext.c_str(),
                            takesFloat ? " or CV_32FC1"
                                       : (" (" + extensionsWhere([](const MosaicContainer& c) {
                                              return c.writes && c.float32;
                                          }) +
                                          " also take CV_32FC1)")
                                             .c_str()));
    MosaicMetadata meta = metadata;
    meta.size = mosaic.size();
    meta.type = mosaic.type();
    const String sidecar = sidecarPathOf(path);
    const std::string text =
        fileStorageText(sidecar, [&](FileStorage& fs) { meta.write(fs, "mosaic_metadata"); });
    const std::vector<uchar> bytes = codec->encode(path, ext, mosaic, meta);
    // Another writer of the same job (a second run into the same folder, started at once) may make the same
    // files at the same time: its image and sidecar, byte for byte ours, are this call's output too.
    const auto holds = [](const String& file, const void* data, size_t size) {
        try {
            return pathExists(file) && readFileBounded(file, static_cast<long long>(size), "file") ==
                                           std::string(static_cast<const char*>(data), size);
        } catch (const Exception&) {
            return false; // larger than ours, or unreadable: not this call's output
        }
    };
    const auto sameSidecar = [&] { return holds(sidecar, text.data(), text.size()); };
    const auto sameImage = [&] { return holds(path, bytes.data(), bytes.size()); };
    if (pathExists(path)) {
        if (sameSidecar() && sameImage())
            return;
        CV_Error(Error::StsError, "writeMosaic: '" + path + "' already exists; it is never overwritten");
    }
    // The sidecar is never replaced either. One left by an interrupted run of the same job (the image
    // missing, the same text) is kept; any other is another mosaic's and stops the write.
    bool createdSidecar = false;
    if (pathExists(sidecar)) {
        if (!sameSidecar())
            CV_Error(Error::StsError, "writeMosaic: '" + sidecar +
                                          "' exists and describes another mosaic; it is never overwritten "
                                          "(remove it if an interrupted run left it)");
    } else {
        try {
            writeFileAtomically(sidecar, text.data(), text.size(), false);
            createdSidecar = true;
        } catch (const Exception&) {
            if (!sameSidecar())
                throw;
        }
    }
    try {
        writeFileAtomically(path, bytes.data(), bytes.size(), false);
    } catch (...) {
        if (sameImage())
            return;
        // No sidecar without its image: a sidecar this call made goes with the failed image, unless an
        // image that another writer made in the meantime now depends on it.
        if (createdSidecar && !pathExists(path))
            detail::removeFileIfPresent(sidecar);
        throw;
    }
}

MosaicMetadata readMosaic(const String& path, OutputArray _mosaic)
{
    const String sidecar = sidecarPathOf(path);
    if (!pathExists(path))
        CV_Error(Error::StsError, "readMosaic: '" + path + "': no such file");
    detail::checkRegularFile(path, "mosaic");
    const MosaicMetadata meta =
        detail::loadFileStorage(sidecar, "mosaic_metadata", "mosaic sidecar",
                                [](const FileNode& n) { return MosaicMetadata::read(n); });
    const ContainerCodec* codec = codecOf(path);
    if (!codec || !codec->container.readsMosaic)
        CV_Error(Error::StsError,
                 "readMosaic: '" + path + "': no mosaic container has its extension; expected " +
                     extensionsWhere([](const MosaicContainer& c) { return c.readsMosaic; }));
    const Mat mosaic = codec->decode(path, meta);
    if (mosaic.empty())
        CV_Error(Error::StsError, "readMosaic: '" + path + "': OpenCV cannot decode it");
    if (mosaic.size() != meta.size || mosaic.type() != meta.type)
        CV_Error(Error::StsError,
                 cv::format("readMosaic: '%s' is %dx%d %s but its sidecar says %dx%d %s", path.c_str(),
                            mosaic.cols, mosaic.rows, typeToString(mosaic.type()).c_str(), meta.size.width,
                            meta.size.height, typeToString(meta.type).c_str()));
    _mosaic.assign(mosaic);
    return meta;
}

} // namespace rawgment
} // namespace cv
