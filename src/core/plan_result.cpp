// What a plan came to (PlanOutcome) and the names of the enums that the CLI and node print.
#include "place_planner/planner.h"

namespace place_planner {

const char* toString(StartKind k) {
  switch (k) {
    case StartKind::kRestingFace: return "resting_face";
    case StartKind::kHeld: return "held";
    case StartKind::kPrincipalAxis: return "principal_axis";
    case StartKind::kAreaTurn: return "area_turn";
    case StartKind::kAxis: return "axis";
    case StartKind::kLoopOnPeg: return "loop_on_peg";
  }
  return "?";
}

const char* toString(SupportKind s) {
  switch (s) {
    case SupportKind::kSeen: return "seen";
    case SupportKind::kCompleted: return "completed";
    case SupportKind::kAreaBorder: return "area_border";
  }
  return "?";
}

const char* toString(PlanOutcome o) {
  switch (o) {
    case PlanOutcome::kStable: return "stable";
    case PlanOutcome::kNoStable: return "no_stable_pose";
    case PlanOutcome::kTimedOutWithStable: return "timed_out_partial";
    case PlanOutcome::kTimedOutNone: return "timed_out";
    case PlanOutcome::kCancelled: return "cancelled";
  }
  return "?";
}

std::string searchedRoots(const PlanStats& st) {
  std::string s;
  if (st.start_orientations > 0)
    s = std::to_string(st.floor_points_done) + " of " + std::to_string(st.floor_points_total) + " floor points";
  if (st.hanging_starts > 0)
    s += (s.empty() ? "" : " and ") + std::to_string(st.hanging_starts_done) + " of " +
         std::to_string(st.hanging_starts) + " threaded starts";
  return s.empty() ? "0 of 0 floor points" : s;
}

int PlanResult::stableCount() const {
  int n = 0;
  for (const Candidate& c : candidates) n += c.stable;
  return n;
}

PlanOutcome PlanResult::outcome() const {
  const bool any = stableCount() > 0;
  if (cancelled) return PlanOutcome::kCancelled;
  if (timed_out) return any ? PlanOutcome::kTimedOutWithStable : PlanOutcome::kTimedOutNone;
  return any ? PlanOutcome::kStable : PlanOutcome::kNoStable;
}

}  // namespace place_planner
