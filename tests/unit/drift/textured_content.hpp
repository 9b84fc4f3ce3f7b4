#pragma once
// Content with texture at every scale a projector shows, for the drift tests: smooth
// noise of several octaves (`cells`: the noise's cell sizes in pixels), summed; a natural
// image's spectrum falls off similarly.
#include <initializer_list>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace procam::drift {

inline cv::Mat texturedContent(cv::Size size, int seed, std::initializer_list<int> cells) {
  cv::Mat sum(size, CV_32F, cv::Scalar(0));
  cv::RNG rng(seed);
  for (int cell : cells) {
    cv::Mat coarse(size.height / cell + 2, size.width / cell + 2, CV_32F);
    rng.fill(coarse, cv::RNG::UNIFORM, 0, 1);
    cv::Mat up;
    cv::resize(coarse, up, cv::Size(coarse.cols * cell, coarse.rows * cell), 0, 0, cv::INTER_CUBIC);
    sum += up(cv::Rect(0, 0, size.width, size.height));
  }
  cv::Mat out;
  sum.convertTo(out, CV_8U, 255.0 / static_cast<double>(cells.size()));
  return out;
}

}  // namespace procam::drift
