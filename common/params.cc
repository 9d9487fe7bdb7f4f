#include "common/params.h"

namespace mjslam {

void ParamChecker::OneOf(std::string_view key, const std::string& value,
                         const std::vector<std::string>& choices) {
  for (const std::string& choice : choices) {
    if (value == choice) return;
  }
  std::string expected = "one of";
  for (std::size_t i = 0; i < choices.size(); ++i) {
    expected += (i == 0 ? " " : ", ") + choices[i];
  }
  Require(false, key, value, expected);
}

void ParamChecker::Merge(std::string_view prefix,
                         const std::vector<ParamProblem>& nested) {
  for (const ParamProblem& problem : nested) {
    problems_.push_back(
        {std::string(prefix) + "." + problem.key, problem.value, problem.expected});
  }
}

void ThrowIfProblems(const std::vector<ParamProblem>& problems,
                     std::string_view context) {
  if (problems.empty()) return;
  std::string message;
  for (const ParamProblem& problem : problems) {
    if (!message.empty()) message += "\n";
    if (!context.empty()) message += std::string(context) + ": ";
    message += problem.key + ": expected " + problem.expected + " (got " +
               problem.value + ")";
  }
  throw ParamError(message);
}

}  // namespace mjslam
