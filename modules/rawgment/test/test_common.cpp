// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <dirent.h>
#include <dlfcn.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace {
std::atomic<long> forkCount{0};
} // namespace

// The test program's own fork(): the library's calls resolve to it before libc's, so a test can tell
// whether a reader started a child (Files.readersStartNoChildProcess).
extern "C" pid_t fork() noexcept
{
    ++forkCount;
    using Fork = pid_t (*)();
    static const Fork next = reinterpret_cast<Fork>(::dlsym(RTLD_NEXT, "fork"));
    return next ? next() : -1;
}

namespace cv {
namespace rawgment {
namespace test {

long forkCalls()
{
    return forkCount.load();
}

std::string findDataFile(const std::string& name)
{
    namespace fs = std::filesystem;
    if (const char* dir = std::getenv("RAWGMENT_TEST_DATA_DIR")) {
        const fs::path p = fs::path(dir) / name;
        if (fs::exists(p))
            return p.string();
    }
    const fs::path p = fs::path(RAWGMENT_SHARED_DATA_DIR) / name;
    return fs::exists(p) ? p.string() : std::string();
}

std::string makeTempDir(const std::string& testName)
{
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("rawgment_test_" + testName);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir.string();
}

int countNonFinite(const Mat& m)
{
    Mat f;
    m.convertTo(f, CV_64F);
    int bad = 0;
    for (auto it = f.begin<double>(); it != f.end<double>(); ++it)
        bad += std::isfinite(*it) ? 0 : 1;
    return bad;
}

SensorParams referenceSensorParams()
{
    SensorParams p;
    p.noise = NoiseModel(0.4, 0.5, 2.0);
    p.blackLevel = Vec4d::all(256);
    p.bitDepth = 12;
    return p;
}

std::vector<char> readBytes(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    return std::vector<char>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::vector<char>& bytes)
{
    std::ofstream f(path, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(f.good()) << "cannot write " << path;
}

std::vector<std::string> filesIn(const std::string& dir)
{
    std::vector<std::string> names;
    DIR* d = opendir(dir.c_str());
    if (!d)
        return names;
    while (dirent* e = readdir(d))
        if (e->d_name[0] != '.')
            names.push_back(e->d_name);
    closedir(d);
    std::sort(names.begin(), names.end());
    return names;
}

SensorParams darkComponentSensorParams(Size size, double lambda, uint64 seed)
{
    SensorParams p = referenceSensorParams();
    p.noise.rowSigmaD2 = 0.3;
    p.noise.rowSigmaR2 = 0.5;
    p.noise.tukeyRead = true;
    p.noise.tukeyLambda = lambda;
    Mat bd(size, CV_32FC1), br(size, CV_32FC1);
    RNG rng(seed);
    rng.fill(bd, RNG::NORMAL, 0, 0.8);
    rng.fill(br, RNG::NORMAL, 0, 2.0);
    for (int c = 0; c < size.width; ++c)
        bd.col(c) += 2.0 * c / size.width;
    p.noise.darkShadingPerGain = bd;
    p.noise.darkShadingOffset = br;
    return p;
}

double poissonChiSquare(const std::map<int64_t, int>& counts, double lambda, double n, int& dof, double* mass)
{
    const auto term = [n](double p, double observed) {
        return (observed - p * n) * (observed - p * n) / (p * n);
    };
    double chi2 = 0, cellP = 0, cellObs = 0, covered = 0, closedP = 0, closedObs = 0, lastP = 0, lastObs = 0;
    dof = -1;
    for (int64_t k = 0; k < 4 * lambda + 60; ++k) {
        const double pk = std::exp(-lambda + static_cast<double>(k) * std::log(lambda) -
                                   std::lgamma(static_cast<double>(k) + 1.0));
        cellP += pk;
        covered += pk;
        const auto it = counts.find(k);
        cellObs += it == counts.end() ? 0 : it->second;
        if (cellP * n >= 20) {
            chi2 += term(cellP, cellObs);
            ++dof;
            closedP += cellP;
            closedObs += cellObs;
            lastP = cellP;
            lastObs = cellObs;
            cellP = cellObs = 0;
        }
    }
    // The rest of the distribution, every count above the last cell (beyond 4 lambda + 59 too), joins
    // that cell, so that an excess of large counts shows.
    double total = 0;
    for (const auto& c : counts)
        total += c.second;
    if (dof >= 0) {
        chi2 += term(lastP + (1 - closedP), lastObs + (total - closedObs)) - term(lastP, lastObs);
    }
    if (mass)
        *mass = covered;
    return chi2;
}

void meanAndStandardError(const std::vector<double>& values, double& mean, double& standardError)
{
    const double n = static_cast<double>(values.size());
    mean = 0;
    for (double x : values)
        mean += x / n;
    double ss = 0;
    for (double x : values)
        ss += (x - mean) * (x - mean);
    standardError = std::sqrt(ss / (n - 1) / n);
}

} // namespace test
} // namespace rawgment
} // namespace cv
