#!/usr/bin/env python3
"""Closed loop: a kinematic car follows the lanes of a generated city, one rendered frame per step.

The caller owns the ego pose: each step it steers toward a point ahead on the lane centre line
(pure pursuit on the lane arrays of ``city.lanes``), moves the car, and renders the frame at its
new pose. At a lane's end it takes the lane that starts nearest ahead (the straightest turn).

    xvfb-run -a python3 examples/python/closed_loop.py --steps 300 --out drive.png
"""
import argparse
import math

import numpy as np

import vista

EYE_HEIGHT = 1.2  # metres, as a car path's eye
LOOKAHEAD = 6.0  # metres ahead on the lane
MAX_SPEED = 8.0  # m/s
MAX_YAW_RATE = 1.0  # rad/s
LINK_RADIUS = 40.0  # a successor lane starts within this distance of the lane's end


def heading_of(dx, dy):
    """vista's heading: radians clockwise from north (+y)."""
    return math.atan2(dx, dy)


class LaneFollower:
    """Pure pursuit along the lanes array: the state is the lane being driven."""

    def __init__(self, lanes, start_lane):
        self.a = np.stack([lanes["x0"], lanes["y0"]], axis=1)
        self.b = np.stack([lanes["x1"], lanes["y1"]], axis=1)
        self.edge = lanes["edge"]
        self.speed_limit = lanes["speed_limit"]
        self.lane = start_lane
        self.next_lane = self._successor(start_lane)

    def _direction(self, i):
        d = self.b[i] - self.a[i]
        return d / max(np.linalg.norm(d), 1e-9)

    def _successor(self, i):
        """The lane starting nearest the end of lane i, going on most straight (never straight back)."""
        end, d = self.b[i], self._direction(i)
        gap = np.linalg.norm(self.a - end, axis=1)
        best, best_cost = None, math.inf
        for j in np.nonzero(gap < LINK_RADIUS)[0]:
            if j == i or self.edge[j] == self.edge[i]:
                continue
            turn = math.acos(float(np.clip(np.dot(d, self._direction(j)), -1.0, 1.0)))
            if turn > math.radians(120):
                continue
            cost = gap[j] + 10.0 * turn
            if cost < best_cost:
                best, best_cost = j, cost
        if best is None:  # a dead end: the lane back along the same street
            back = [j for j in np.nonzero(self.edge == self.edge[i])[0] if j != i]
            best = back[0] if back else i
        return int(best)

    def target(self, xy):
        """The point LOOKAHEAD metres ahead of xy's projection on the lane (on into the next lane)."""
        a, b = self.a[self.lane], self.b[self.lane]
        d = b - a
        length = max(float(np.linalg.norm(d)), 1e-9)
        s = float(np.dot(xy - a, d)) / length
        if s >= length:  # past the end: drive the next lane
            self.lane, self.next_lane = self.next_lane, self._successor(self.next_lane)
            return self.target(xy)
        ahead = s + LOOKAHEAD
        if ahead <= length:
            return a + d / length * ahead
        n = self.next_lane
        return self.a[n] + self._direction(n) * min(ahead - length, float(np.linalg.norm(self.b[n] - self.a[n])))


def drive(city, steps=300, dt=1.0 / 30.0, size=(320, 240), mode="full"):
    """Drives `steps` steps from the longest lane's start; returns {"poses", "frames"} (rgb per step)."""
    lanes = city.lanes
    length = np.hypot(lanes["x1"] - lanes["x0"], lanes["y1"] - lanes["y0"])
    start = int(np.argmax(length))
    follower = LaneFollower(lanes, start)
    xy = np.array([lanes["x0"][start], lanes["y0"][start]], dtype=float)
    heading = heading_of(lanes["x1"][start] - lanes["x0"][start], lanes["y1"][start] - lanes["y0"][start])
    renderer = vista.Renderer(city, mode=mode, size=size, channels=["rgb"])
    poses, frames = [], []
    for k in range(steps):
        speed = min(MAX_SPEED, float(follower.speed_limit[follower.lane]))
        goal = follower.target(xy)
        # Pure pursuit: the arc through the goal point; its yaw rate limited.
        alpha = heading_of(*(goal - xy)) - heading
        alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
        yaw_rate = float(np.clip(2.0 * speed * math.sin(alpha) / LOOKAHEAD, -MAX_YAW_RATE, MAX_YAW_RATE))
        heading += yaw_rate * dt
        xy = xy + speed * dt * np.array([math.sin(heading), math.cos(heading)])
        pose = vista.Pose((float(xy[0]), float(xy[1]), EYE_HEIGHT), heading=heading, pitch=0.0, t=k * dt)
        frame = renderer.render(pose)  # the closed loop: a perception stack would read this frame
        poses.append(pose)
        frames.append(frame["rgb"])
    return {"poses": poses, "frames": frames}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--size-m", type=float, default=400)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--out", help="write the last frame and the drive's track as PNG (needs python3-pil)")
    a = ap.parse_args()
    city = vista.generate(seed=a.seed, size_m=a.size_m)
    log = drive(city, steps=a.steps)
    xy = np.array([p.position[:2] for p in log["poses"]])
    print("drove %d steps, %.1f m" % (len(xy), np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))))
    if a.out:
        from PIL import Image

        Image.fromarray(np.ascontiguousarray(log["frames"][-1])).save(a.out)
        print("last frame ->", a.out)


if __name__ == "__main__":
    main()
