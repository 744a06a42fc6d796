// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Included by OpenCV's Python binding (cv2) when rawgment is built as an extra module: the names the
// generated code gives to vectors of the module's structs.
#ifdef HAVE_OPENCV_RAWGMENT
typedef std::vector<cv::rawgment::NoiseSample> vector_NoiseSample;
typedef std::vector<cv::rawgment::ShapiroWilkResult> vector_ShapiroWilkResult;
typedef std::vector<cv::rawgment::CameraNoiseProfile> vector_CameraNoiseProfile;
#endif
