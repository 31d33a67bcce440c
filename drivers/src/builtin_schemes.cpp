// The schemes drivers provides itself. Each source's translation unit exposes a factory.
#include <map>

#include "romo/drivers/frame_source.hpp"

namespace romo::drivers {

std::unique_ptr<FrameSource> OpenGigeSource(const Uri& uri);  // gige_source.cpp
std::unique_ptr<FrameSource> OpenLogSource(const Uri& uri);   // log_reader.cpp
std::unique_ptr<FrameSource> OpenRgbdSource(const Uri& uri);  // rgbd_source.cpp
std::unique_ptr<FrameSource> OpenKinectSource(const Uri& uri);  // kinect_source.cpp

void RegisterBuiltinSchemes(std::map<std::string, SourceFactory>* factories) {
  // Sources add themselves here as they are implemented: (*factories).emplace("log", ...).
  factories->emplace("gige", &OpenGigeSource);
  factories->emplace("log", &OpenLogSource);
  factories->emplace("rgbd", &OpenRgbdSource);
  factories->emplace("kinect", &OpenKinectSource);
}

}  // namespace romo::drivers
