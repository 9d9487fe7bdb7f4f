// PNG round trip, the MP4 read back by ffprobe, no partial files, the params.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "renders/image.h"
#include "renders/render_params.h"
#include "renders/video_writer.h"

namespace mjslam::renders {
namespace {

namespace fs = std::filesystem;

std::string TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("mjslam_renders_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

Image Solid(int width, int height, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  Image image;
  image.width = width;
  image.height = height;
  for (int i = 0; i < width * height; ++i) image.rgb.insert(image.rgb.end(), {r, g, b});
  return image;
}

std::string Output(const std::string& command) {
  std::string text;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  char buffer[256];
  while (pipe && fgets(buffer, sizeof(buffer), pipe.get()) != nullptr) text += buffer;
  return text;
}

TEST(ImageTest, PngRoundTripKeepsEveryPixel) {
  Image image = Solid(7, 5, 10, 20, 30);
  image.rgb[3 * (2 * 7 + 3) + 1] = 200;  // pixel (3, 2), green
  const std::string path = TempPath("round_trip.png");
  WritePng(path, image);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const Image back = ReadPng(path);
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgb, image.rgb);
  EXPECT_EQ(back.At(3, 2, 1), 200);
}

TEST(ImageTest, UnwritablePathThrowsNamingIt) {
  try {
    WritePng("/nonexistent_folder/x.png", Solid(4, 4, 0, 0, 0));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent_folder/x.png"), std::string::npos);
  }
}

TEST(VideoWriterTest, FfprobeReadsFrameCountAndSize) {
  const std::string path = TempPath("five.mp4");
  fs::remove(path);
  VideoWriter video(path, 64, 48, 10.0, 23);
  for (int i = 0; i < 5; ++i) video.AddFrame(Solid(64, 48, static_cast<std::uint8_t>(50 * i), 100, 150));
  EXPECT_FALSE(fs::exists(path));  // only the temporary file until Finish
  video.Finish();
  ASSERT_TRUE(fs::exists(path));
  const std::string probe = Output(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,nb_read_frames -of default=noprint_wrappers=1 " + path);
  EXPECT_NE(probe.find("codec_name=h264"), std::string::npos) << probe;
  EXPECT_NE(probe.find("width=64"), std::string::npos) << probe;
  EXPECT_NE(probe.find("height=48"), std::string::npos) << probe;
  EXPECT_NE(probe.find("nb_read_frames=5"), std::string::npos) << probe;
}

TEST(VideoWriterTest, UnfinishedVideoLeavesNoFile) {
  const std::string path = TempPath("unfinished.mp4");
  fs::remove(path);
  {
    VideoWriter video(path, 32, 32, 10.0, 23);
    video.AddFrame(Solid(32, 32, 1, 2, 3));
  }  // destroyed before Finish, as on an error or an interrupt
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp.mp4"));
}

TEST(RenderParamsTest, RejectsOddSizesAndBadRates) {
  RenderParams params;
  EXPECT_TRUE(params.Validate().empty());
  params.width = 641;
  params.fps = 0.0;
  const std::vector<ParamProblem> problems = params.Validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].key, "width");
  EXPECT_EQ(problems[0].value, "641");
  EXPECT_EQ(problems[1].key, "fps");
}

}  // namespace
}  // namespace mjslam::renders
