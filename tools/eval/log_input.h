#pragma once
// Trajectories from LCM logs: the LCM side of the evaluation (library kestrel_eval_log; the
// metrics, kestrel_metrics, and the rest of kestrel_eval know nothing of LCM).
//
// A channel holds one of four message types, each giving a trajectory:
//  * ground_truth_t (GROUND_TRUTH): T_world_frame, of the body or the camera as the message
//    says (every message on the channel must say the same);
//  * state_t (STATE): T_world_body; frames with status INITIALIZING or FAILED have no estimate;
//  * vo_update_t (VO_UPDATE): motions chained into T_world_camera by VoChain (vo_chain.h);
//    the camera mounting T_body_camera is taken from the first such message;
//  * slam_graph_t (SLAM_GRAPH): the keyframes' optimised T_world_camera in the graph of the
//    highest revision (the final map), one pose per keyframe; a graph of a lower revision
//    after a higher one is counted as out of order. A SLAM process restarted in flight starts
//    a new session whose graphs share no keyframe with the old one's: the trajectory is then
//    each session's final graph, one after the other.
// The standard channel names fix the type; any other channel takes the type of its first
// message of one of the four. Time is the messages' utime, not the log's time stamps.
//
// Bad input is counted, not fatal, wherever the rest can still be used: a damaged log is read
// up to and around the damage (LogReader), a message of another type, a corrupt message, a
// non-finite pose or a time stamp not after the previous one is skipped and counted in
// InputDiagnostics.

#include <string>
#include <vector>

#include "tools/eval/trajectory_input.h"

namespace kestrel::eval {

/// True if `path` starts with an LCM log event header (the kind is told by content, never
/// by the file name); false for anything else, e.g. a text file. InputError if unreadable.
bool is_lcm_log(const std::string& path);

/// Reads the trajectory on the first of `channels` that has events in the log at `path`.
/// Throws InputError (naming the file and the channels present) when none has, when the log
/// cannot be read, or when the ground-truth frame changes along the channel.
TrajectoryInput read_log_input(const std::string& path, const std::vector<std::string>& channels);

}  // namespace kestrel::eval
