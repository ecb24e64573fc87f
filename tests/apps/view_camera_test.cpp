// The camera moves of `eikon view` (apps/view_camera.h) against their geometry: an orbit keeps the
// distance to look_at and turns the offset by the angle asked for, a pan moves camera and look_at
// together in the image plane, a zoom scales the distance; the camera JSON reads back.
#include "apps/view_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

namespace {

using eikon::Camera;
Camera camera() {
  Camera c;
  c.position = {0, 0, -60};
  c.look_at = {0, 0, 0};
  c.up = {0, 1, 0};
  c.fov_deg = 30;
  return c;
}

TEST(ViewCamera, YawTurnsAboutUpKeepingDistance) {
  Camera c = camera();
  eikon::cli::orbitCamera(c, 0.5 * std::numbers::pi, 0.0);
  EXPECT_NEAR(glm::length(c.position - c.look_at), 60.0, 1e-12);
  EXPECT_NEAR(c.position.y, 0.0, 1e-12);
  EXPECT_NEAR(std::abs(c.position.x), 60.0, 1e-12);  // a quarter turn: onto the x axis
  EXPECT_NEAR(c.position.z, 0.0, 1e-12);
  for (int i = 0; i < 3; ++i)
    eikon::cli::orbitCamera(c, 0.5 * std::numbers::pi, 0.0);  // a full turn
  EXPECT_NEAR(c.position.x, 0.0, 1e-11);
  EXPECT_NEAR(c.position.z, -60.0, 1e-11);
}

TEST(ViewCamera, PitchRaisesTheCameraAndStopsShortOfThePole) {
  Camera c = camera();
  eikon::cli::orbitCamera(c, 0.0, std::numbers::pi / 6);
  EXPECT_NEAR(glm::length(c.position - c.look_at), 60.0, 1e-12);
  EXPECT_NEAR(c.position.y, 60.0 * std::sin(std::numbers::pi / 6), 1e-10);
  eikon::cli::orbitCamera(c, 0.0, std::numbers::pi);  // past the pole: held 1° short
  EXPECT_NEAR(c.position.y, 60.0 * std::cos(std::numbers::pi / 180), 1e-9);
  EXPECT_LT(c.position.z, 0.0);  // still on the side it started
}

TEST(ViewCamera, PanMovesCameraAndLookAtTogether) {
  Camera c = camera();
  eikon::cli::panCamera(c, 0.25, -0.5);
  const double height =
      2.0 * 60.0 * std::tan(15.0 * std::numbers::pi / 180.0);  // image height at look_at
  // Looking along +z with up +y, the image's right is −x.
  EXPECT_NEAR(c.look_at.x, -0.25 * height, 1e-12);
  EXPECT_NEAR(c.look_at.y, -0.5 * height, 1e-12);
  EXPECT_NEAR(c.look_at.z, 0.0, 1e-12);
  EXPECT_NEAR(glm::length(c.position - c.look_at - glm::dvec3(0, 0, -60)), 0.0, 1e-12);
}

TEST(ViewCamera, ZoomScalesTheDistance) {
  Camera c = camera();
  eikon::cli::zoomCamera(c, 0.5);
  EXPECT_NEAR(c.position.z, -30.0, 1e-12);
  EXPECT_EQ(c.look_at, glm::dvec3(0.0));
}

TEST(ViewCamera, PointLightFollowsTheCursorInItsDepthPlane) {
  Camera c = camera();
  eikon::Light l;
  l.type = eikon::Light::Type::Point;
  l.position = {0, 10, 40};  // 100 mm in front of the camera
  eikon::cli::moveLight(l, c, 0.1, 0.2);
  const double height = 2.0 * 100.0 * std::tan(15.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(l.position.x, -0.1 * height, 1e-12);  // the image's right is -x
  EXPECT_NEAR(l.position.y, 10 + 0.2 * height, 1e-12);
  EXPECT_NEAR(l.position.z, 40.0, 1e-12);
}

TEST(ViewCamera, DirectionalLightTurnsKeepingUnitLength) {
  Camera c = camera();
  eikon::Light l;
  l.direction = {0, -1, 0};
  eikon::cli::moveLight(l, c, 0.0,
                        std::numbers::pi / 6 / 3.0);  // dy of 1/18 window heights: 30 degrees
  EXPECT_NEAR(glm::length(l.direction), 1.0, 1e-12);
  EXPECT_NEAR(std::acos(-l.direction.y), std::numbers::pi / 6, 1e-12);
  EXPECT_NEAR(l.direction.x, 0.0, 1e-12);  // turned about the camera's right axis (x)
}

TEST(ViewCamera, JsonReadsBackAsTheSceneCamera) {
  Camera c = camera();
  eikon::cli::orbitCamera(c, 0.3, 0.2);
  const auto j = nlohmann::json::parse(eikon::cli::cameraJson(c, 400, 300));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["position"][i].get<double>(), c.position[i], 1e-7 * 60);
    EXPECT_NEAR(j["up"][i].get<double>(), c.up[i], 1e-9);
  }
  EXPECT_EQ(j["fov_deg"].get<double>(), 30.0);
  EXPECT_EQ(j["width"].get<int>(), 400);
  EXPECT_EQ(j["height"].get<int>(), 300);
}

}  // namespace
