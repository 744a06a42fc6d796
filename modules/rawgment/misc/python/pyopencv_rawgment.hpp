// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Included by OpenCV's Python binding (cv2) when rawgment is built as an extra module: the names the
// generated code gives to vectors of the module's structs.
#ifdef HAVE_OPENCV_RAWGMENT
typedef std::vector<cv::rawgment::NoiseSample> vector_NoiseSample;
typedef std::vector<cv::rawgment::ShapiroWilkResult> vector_ShapiroWilkResult;
typedef std::vector<cv::rawgment::CameraNoiseProfile> vector_CameraNoiseProfile;
typedef std::vector<cv::rawgment::Emva1288Images> vector_Emva1288Images;
typedef std::vector<cv::rawgment::Emva1288Pair> vector_Emva1288Pair;
typedef std::vector<cv::rawgment::Emva1288Stack> vector_Emva1288Stack;
typedef std::vector<cv::rawgment::Emva1288Results> vector_Emva1288Results;
typedef std::vector<cv::rawgment::Emva1288Darkening> vector_Emva1288Darkening;
#endif
