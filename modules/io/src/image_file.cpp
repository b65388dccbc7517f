#include "omnislam/io/image_file.hpp"

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <system_error>

namespace omnislam::io {

cv::Mat read_camera_image(const std::filesystem::path &file, const mirror::MirrorConfig &camera) {
  const std::string name = file.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) {
    throw std::runtime_error(name + ": no such image file");
  }
  if (std::filesystem::file_size(file, error) == 0) {
    throw std::runtime_error(name + ": image file is empty");
  }
  cv::Mat image = cv::imread(name, cv::IMREAD_GRAYSCALE);
  if (image.empty()) {
    throw std::runtime_error(name + ": not a readable image (unknown format or corrupt)");
  }
  if (image.cols != camera.image_width_px || image.rows != camera.image_height_px) {
    throw std::runtime_error(name + ": image is " + std::to_string(image.cols) + "x" +
                             std::to_string(image.rows) + " px, the camera is configured for " +
                             std::to_string(camera.image_width_px) + "x" +
                             std::to_string(camera.image_height_px));
  }
  return image;
}

void write_png_image(const std::filesystem::path &file, const cv::Mat &image) {
  const std::string name = file.string();
  bool written = false;
  try {
    written = cv::imwrite(name, image, {cv::IMWRITE_PNG_COMPRESSION, 3});
  } catch (const cv::Exception &error) {
    throw std::runtime_error(name + ": cannot write the PNG image: " + error.what());
  }
  if (!written) throw std::runtime_error(name + ": cannot write the PNG image");
}

}  // namespace omnislam::io
