"""A knowledge-base writer for the crash test: writes frames forever, printing each committed
pose id; the test kills it with SIGKILL at random instants.

Usage: kb_crash_writer.py KB_DIR [inline|follower]. ``inline`` syncs the graph every 4 frames
through the bulk loader (threshold 0: every sync is a non-atomic bulk load); ``follower`` leaves
the graph to a ``GraphFollower`` process syncing every 20 ms."""

from __future__ import annotations

import sys

import numpy as np

from hiper_cli.graph import open_kb, scenegraph
from hiper_cli.graph.follower import GraphFollower
from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.perceive.stage import FrameResult

OBS_PER_FRAME = 3


def main(path: str, mode: str = "inline") -> None:
    scenegraph.BULK_MIN_BYTES = 0
    kb = open_kb(path)  # catches the graph up with the documents: the repair after a crash
    if mode == "follower":
        GraphFollower(kb, interval_s=0.02).start()
    env = kb.environment("crash")
    session = kb.resumable_session(env, "crashlog") or kb.start_session(env, "crashlog", ["writer"])
    world = kb.load_world(env)
    inst = next(iter(world.foreground.values()), None) or Instance(
        "foreground", "cup", Box3D(np.zeros(3), np.ones(3)), 0.0, 0.0)
    pose = -1 if session.last_pose_id is None else session.last_pose_id
    print("ready", pose, flush=True)
    T = np.eye(4)
    while True:
        pose += 1
        obs = [Observation("foreground", "cup", 0.5, float(pose), pose, Box3D(np.ones(3), np.ones(3)),
                           instance_uuid=inst.uuid, data={"blob": list(range(50))})
               for _ in range(OBS_PER_FRAME)]
        inst.observation_uuids += [o.uuid for o in obs]
        inst.last_seen_s = float(pose)
        kb.write_frame(session, FrameResult(obs, [inst]), pose_id=pose, stamp_s=float(pose), T_map_cam=T)
        print(pose, flush=True)
        if pose % 4 == 0 and mode == "inline":
            kb.sync_graph()


if __name__ == "__main__":
    main(*sys.argv[1:])
