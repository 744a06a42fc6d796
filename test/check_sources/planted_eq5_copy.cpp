// A planted copy of Eq. 5 for the test check_sources_catches_a_copy_of_eq5: scripts/check-sources.sh
// must refuse it when it is given this file (the whole-tree run exempts test/).
double readVariance(double g, const cv::rawgment::NoiseModel& model)
{
    return g * g * model.sigmaD2 + model.sigmaR2;
}
