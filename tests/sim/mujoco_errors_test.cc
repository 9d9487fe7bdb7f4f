// MuJoCo's errors and warnings reach C++ callers as messages and exceptions
// without any exception crossing MuJoCo's C frames: the error handler
// longjmps back to the trap around the call (sim/mujoco_errors.h).

#include <string>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "sim/mujoco_errors.h"
#include "sim/scene_model.h"
#include "tests/sim/sim_test_util.h"

namespace mjslam::sim {
namespace {

using testing::MujocoTest;
using testing::WriteTempFile;

// A one-body model loaded directly with MuJoCo.
internal::ModelPtr LoadBall() {
  const std::string path = WriteTempFile(
      "ball.xml", "<mujoco><worldbody><geom type=\"plane\" size=\"5 5 0.1\"/>"
                  "<body pos=\"0 0 1\"><freejoint/><geom type=\"sphere\" size=\"0.1\"/></body>"
                  "</worldbody></mujoco>");
  char error[1024] = "";
  internal::ModelPtr model(mj_loadXML(path.c_str(), nullptr, error, sizeof(error)));
  EXPECT_NE(model, nullptr) << error;
  return model;
}

class MujocoErrorsTest : public MujocoTest {};

TEST_F(MujocoErrorsTest, AnErrorInsideATrappedCallComesBackAsItsMessage) {
  bool finished = false;
  auto call = [&] {
    mju_error("test error 42");
    finished = true;  // never reached: mju_error does not return
  };
  EXPECT_EQ(TrapMujocoErrors(call), "MuJoCo error: test error 42");
  EXPECT_FALSE(finished);
  // A call without an error.
  auto fine = [&] { finished = true; };
  EXPECT_EQ(TrapMujocoErrors(fine), "");
  EXPECT_TRUE(finished);
}

TEST_F(MujocoErrorsTest, AWarningLetsTheCallFinishAndIsReported) {
  bool finished = false;
  auto call = [&] {
    mju_warning("first warning");
    mju_warning("second warning");
    finished = true;
  };
  EXPECT_EQ(TrapMujocoErrors(call), "MuJoCo warning: first warning");
  EXPECT_TRUE(finished);
  // The next call starts clean.
  auto fine = [] {};
  EXPECT_EQ(TrapMujocoErrors(fine), "");
}

// MuJoCo itself raises the error, deep inside its C code (its stack
// allocator), and the process keeps using MuJoCo afterwards.
TEST_F(MujocoErrorsTest, AnErrorRaisedByMujocoBecomesASimErrorAndMujocoStaysUsable) {
  const internal::ModelPtr model = LoadBall();
  ASSERT_NE(model, nullptr);
  const internal::DataPtr data = internal::MakeData(*model, "test");
  mjData* d = data.get();
  std::string message;
  try {
    CallMujoco("allocating too much", [&] { mj_stackAlloc(d, 1 << 30); });
  } catch (const SimError& error) {
    message = error.what();
  }
  EXPECT_EQ(message.rfind("allocating too much: MuJoCo error: ", 0), 0u) << message;
  EXPECT_GT(message.size(), std::string("allocating too much: MuJoCo error: ").size());
  // Fresh data for the same model: the ball falls, as it should.
  const internal::DataPtr fresh = internal::MakeData(*model, "test");
  mjData* f = fresh.get();
  CallMujoco("stepping", [&] {
    for (int i = 0; i < 100; ++i) mj_step(model.get(), f);
  });
  EXPECT_LT(f->qpos[2], 1.0);
  EXPECT_GT(f->time, 0.0);
}

TEST_F(MujocoErrorsTest, CallMujocoThrowsForWarningsToo) {
  EXPECT_THROW(CallMujoco("warning", [] { mju_warning("careful"); }), SimError);
  try {
    CallMujoco("warning", [] { mju_warning("careful"); });
  } catch (const SimError& error) {
    EXPECT_STREQ(error.what(), "warning: MuJoCo warning: careful");
  }
}

TEST_F(MujocoErrorsTest, NestedTrapsReturnToTheInnermost) {
  std::string inner;
  bool outer_finished = false;
  auto inner_call = [] { mju_error("inner"); };
  auto outer_call = [&] {
    inner = TrapMujocoErrors(inner_call);
    outer_finished = true;
  };
  // The outer body creates a std::string (inner's result) only after the
  // inner trap returned normally; nothing is skipped.
  EXPECT_EQ(TrapMujocoErrors(outer_call), "");
  EXPECT_EQ(inner, "MuJoCo error: inner");
  EXPECT_TRUE(outer_finished);
}

TEST_F(MujocoErrorsTest, InstallingReplacesOtherHandlers) {
  mju_user_error = nullptr;
  mju_user_warning = nullptr;
  InstallMujocoErrorHandlers();
  EXPECT_NE(mju_user_error, nullptr);
  EXPECT_NE(mju_user_warning, nullptr);
  auto call = [] { mju_error("after reinstalling"); };
  EXPECT_EQ(TrapMujocoErrors(call), "MuJoCo error: after reinstalling");
}

TEST(MujocoErrorsDeathTest, AnErrorOutsideATrappedCallAbortsWithItsMessage) {
  InstallMujocoErrorHandlers();
  EXPECT_DEATH(mju_error("untrapped"), "MuJoCo error outside a trapped call.*untrapped");
}

}  // namespace
}  // namespace mjslam::sim
