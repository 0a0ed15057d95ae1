"""tf2 checked from outside: imports only tf2_ros, tf2_geometry_msgs, rclpy, numpy, pytransform3d.

Run as a program (``python tests/tf2/outside_check.py SEED``) by
test_tf2_outside.py. Random trees of 25 frames with random stamps; every
lookup is compared with the same chain composed independently with
pytransform3d (slerp and matrices), including interpolation, time zero
(latest common time), time travel (lookup_transform_full), static frames,
the cache's length, bad input, and each exception with tf2's wording.
Prints ``OK <checks>``; any mismatch raises.
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytransform3d.rotations as pr
import pytransform3d.transformations as pt
import tf2_geometry_msgs  # noqa: F401  (registers the geometry_msgs types)
import tf2_ros
from geometry_msgs.msg import PointStamped, PoseStamped, TransformStamped, Vector3Stamped
from rclpy.duration import Duration
from rclpy.time import Time
from tf2_geometry_msgs import do_transform_point, do_transform_pose, do_transform_vector3

NS = 1_000_000_000
checks = 0


def check(condition: bool, what: str) -> None:
    global checks
    checks += 1
    if not condition:
        raise AssertionError(what)


def raises(exc: type[Exception], message: str, fn, *args) -> None:  # type: ignore[no-untyped-def]
    try:
        fn(*args)
    except exc as e:
        check(str(e) == message, f"{exc.__name__} wording:\n  got  {str(e)!r}\n  want {message!r}")
        return
    except Exception as e:
        raise AssertionError(f"expected {exc.__name__}, got {type(e).__name__}: {e}") from e
    raise AssertionError(f"expected {exc.__name__}, nothing raised")


class Tree:
    """The random tree and its independent evaluation."""

    def __init__(self, rng: np.random.Generator, n: int = 25) -> None:
        self.parent: dict[str, str] = {}
        self.static: dict[str, np.ndarray] = {}  # frame -> 4x4
        self.samples: dict[str, list[tuple[int, np.ndarray, np.ndarray]]] = {}  # (ns, p, q wxyz)
        names = ["root"] + [f"f{i}" for i in range(1, n)]
        for i, name in enumerate(names[1:], start=1):
            self.parent[name] = names[int(rng.integers(0, i))]
            if rng.random() < 0.3:
                self.static[name] = pt.transform_from_pq(
                    np.r_[rng.uniform(-2, 2, 3), pr.random_quaternion(rng)]
                )
            else:
                stamps = sorted(
                    {int(s) for s in rng.integers(100 * NS, 104 * NS, rng.integers(2, 12))}
                )
                stamps = sorted(
                    set(stamps)
                    | {int(rng.integers(99 * NS, 100 * NS)), 104 * NS + int(rng.integers(0, NS))}
                )
                self.samples[name] = [
                    (s, rng.uniform(-2, 2, 3), pr.random_quaternion(rng)) for s in stamps
                ]

    def local(self, frame: str, t: int) -> np.ndarray:
        if frame in self.static:
            return self.static[frame]
        samples = self.samples[frame]
        for (t0, p0, q0), (t1, p1, q1) in zip(samples, samples[1:], strict=False):
            if t0 <= t <= t1:
                r = (t - t0) / (t1 - t0)
                q = pr.quaternion_slerp(q0, q1, r, shortest_path=True)
                return pt.transform_from_pq(np.r_[p0 + (p1 - p0) * r, q])
        raise ValueError("outside the samples")

    def to_root(self, frame: str, t: int, top: str = "root") -> np.ndarray:
        m = np.eye(4)
        while frame != top:
            m = self.local(frame, t) @ m
            frame = self.parent[frame]
        return m

    def path(self, frame: str) -> list[str]:
        out = [frame]
        while frame != "root":
            frame = self.parent[frame]
            out.append(frame)
        return out

    def latest_common(self, a: str, b: str) -> int:
        pa, pb = self.path(a), self.path(b)
        common = next(f for f in pa if f in pb)
        frames = pa[: pa.index(common)] + pb[: pb.index(common)]
        latest = [self.samples[f][-1][0] for f in frames if f in self.samples]
        return min(latest) if latest else 0

    def messages(self) -> list[tuple[TransformStamped, bool]]:
        out = []
        for child, m in self.static.items():
            out.append((msg(self.parent[child], child, 0, m), True))
        for child, samples in self.samples.items():
            for s, p, q in samples:
                out.append(
                    (msg(self.parent[child], child, s, pt.transform_from_pq(np.r_[p, q])), False)
                )
        return out


def msg(parent: str, child: str, stamp: int, m: np.ndarray) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp.sec, t.header.stamp.nanosec = divmod(stamp, NS)
    pq = pt.pq_from_transform(m)
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = pq[:3]
    w, x, y, z = pq[3:]
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z = x, y, z
    t.transform.rotation.w = w
    return t


def matrix(t: TransformStamped) -> np.ndarray:
    tr, r = t.transform.translation, t.transform.rotation
    return pt.transform_from_pq(np.array([tr.x, tr.y, tr.z, r.w, r.x, r.y, r.z]))


def same(a: np.ndarray, b: np.ndarray, what: str) -> None:
    check(np.allclose(a, b, atol=1e-9), f"{what}:\n{a}\n!=\n{b}")


def check_tree(rng: np.random.Generator) -> None:
    tree = Tree(rng)
    buf = tf2_ros.Buffer()
    items = tree.messages()
    rng.shuffle(items)  # out-of-order arrival is normal on /tf
    for m, is_static in items:
        stored = (buf.set_transform_static if is_static else buf.set_transform)(m, "outside")
        check(stored, "a well-formed transform is stored")
    frames = list(tree.parent) + ["root"]
    for _ in range(150):
        a, b = (str(f) for f in rng.choice(frames, 2, replace=False))
        lct = tree.latest_common(a, b)
        got = buf.lookup_transform(a, b, Time())  # time zero: latest common time
        check(got.header.stamp.sec * NS + got.header.stamp.nanosec == lct, f"time zero {a}<-{b}")
        check((got.header.frame_id, got.child_frame_id) == (a, b), "header names the frames")
        if lct:  # only the frames up to the common ancestor need data at that time
            top = next(f for f in tree.path(a) if f in tree.path(b))
            want = np.linalg.inv(tree.to_root(a, lct, top)) @ tree.to_root(b, lct, top)
            same(matrix(got), want, f"latest {a}<-{b}")
        t = int(rng.integers(100 * NS, 104 * NS))  # inside every dynamic frame's samples
        got = buf.lookup_transform(a, b, Time(nanoseconds=t), timeout=Duration(seconds=0.0))
        same(
            matrix(got),
            np.linalg.inv(tree.to_root(a, t)) @ tree.to_root(b, t),
            f"interpolated {a}<-{b}",
        )
        check(buf.can_transform(a, b, Time(nanoseconds=t)), "can_transform agrees")
        t2 = int(rng.integers(100 * NS, 104 * NS))
        got = buf.lookup_transform_full(a, Time(nanoseconds=t), b, Time(nanoseconds=t2), "root")
        same(
            matrix(got),
            np.linalg.inv(tree.to_root(a, t)) @ tree.to_root(b, t2),
            f"time travel {a}@{t} <- {b}@{t2}",
        )
        check(
            buf.can_transform_full(a, Time(nanoseconds=t), b, Time(nanoseconds=t2), "root"),
            "can_full",
        )
        # geometry through buffer.transform at the point's own stamp
        p = PointStamped()
        p.header.frame_id = b
        p.header.stamp.sec, p.header.stamp.nanosec = divmod(t, NS)
        p.point.x, p.point.y, p.point.z = (float(v) for v in rng.uniform(-3, 3, 3))
        out = buf.transform(p, a)
        want = (
            np.linalg.inv(tree.to_root(a, t))
            @ tree.to_root(b, t)
            @ np.r_[p.point.x, p.point.y, p.point.z, 1.0]
        )
        check(
            np.allclose([out.point.x, out.point.y, out.point.z], want[:3], atol=1e-9),
            "transform(point)",
        )
        check(out.header.frame_id == a, "transformed point is in the target frame")
    # a static frame answers at any time, even far outside every cache
    s = next(iter(tree.static))
    got = buf.lookup_transform(tree.parent[s], s, Time(seconds=5000))
    same(matrix(got), tree.static[s], "static frame at any time")
    # extrapolation, both ways, with tf2's wording
    d = next(iter(tree.samples))
    first, last = tree.samples[d][0][0], tree.samples[d][-1][0]
    parent = tree.parent[d]
    raises(
        tf2_ros.ExtrapolationException,
        "Lookup would require extrapolation into the future.  Requested time "
        f"{(last + NS) / 1e9:.6f} but the latest data is at time {last / 1e9:.6f}, when looking up "
        f"transform from frame [{d}] to frame [{parent}]",
        buf.lookup_transform,
        parent,
        d,
        Time(nanoseconds=last + NS),
    )
    raises(
        tf2_ros.ExtrapolationException,
        "Lookup would require extrapolation into the past.  Requested time "
        f"{(first - NS) / 1e9:.6f} but the earliest data is at time {first / 1e9:.6f}, when "
        f"looking up transform from frame [{d}] to frame [{parent}]",
        buf.lookup_transform,
        parent,
        d,
        Time(nanoseconds=first - NS),
    )
    check(not buf.can_transform(parent, d, Time(nanoseconds=last + NS)), "can_transform says no")


def check_errors_and_bad_input() -> None:
    buf = tf2_ros.Buffer()
    eye = np.eye(4)
    buf.set_transform(msg("world", "a", 10 * NS, eye), "me")
    buf.set_transform(msg("island", "b", 10 * NS, eye), "me")
    raises(
        tf2_ros.LookupException,
        '"nowhere" passed to lookupTransform argument source_frame does not exist. ',
        buf.lookup_transform,
        "world",
        "nowhere",
        Time(),
    )
    raises(
        tf2_ros.LookupException,
        '"turtle1" passed to lookupTransform argument target_frame does not exist. ',
        buf.lookup_transform,
        "turtle1",
        "a",
        Time(),
    )
    raises(
        tf2_ros.ConnectivityException,
        "Could not find a connection between 'world' and 'b' because they are not part of the "
        "same tree.Tf has two or more unconnected trees.",
        buf.lookup_transform,
        "world",
        "b",
        Time(),
    )
    raises(
        tf2_ros.InvalidArgumentException,
        'Invalid argument "" passed to lookupTransform argument target_frame - in tf2 frame_ids '
        "cannot be empty",
        buf.lookup_transform,
        "",
        "a",
        Time(),
    )
    raises(
        tf2_ros.InvalidArgumentException,
        'Invalid argument "/a" passed to lookupTransform argument source_frame - in tf2 '
        "frame_ids cannot start with a '/'",
        buf.lookup_transform,
        "world",
        "/a",
        Time(),
    )
    raises(
        tf2_ros.ExtrapolationException,
        "Lookup would require extrapolation at time 11.000000, but only time 10.000000 is in the "
        "buffer, when looking up transform from frame [a] to frame [world]",
        buf.lookup_transform,
        "world",
        "a",
        Time(seconds=11),
    )
    check(issubclass(tf2_ros.TimeoutException, tf2_ros.TransformException), "hierarchy")
    ok, why = buf.can_transform("world", "ghost", Time(), return_debug_tuple=True)
    check(
        (ok, why)
        == (
            False,
            'Invalid frame ID "ghost" passed to canTransform argument source_frame - '
            "frame does not exist",
        ),
        f"can_transform debug tuple {why!r}",
    )
    # waiting: a timeout returns after about that long, then tf2's exception
    import time as _t

    start = _t.monotonic()
    raises(
        tf2_ros.LookupException,
        '"late" passed to lookupTransform argument source_frame does not exist. ',
        buf.lookup_transform,
        "world",
        "late",
        Time(),
        Duration(seconds=0.3),
    )
    check(0.25 <= _t.monotonic() - start < 2.0, "lookup waited for its timeout")
    # bad input is refused, never stored, never a crash
    nan = msg("world", "n", 10 * NS, eye)
    nan.transform.translation.y = math.nan
    check(buf.set_transform(nan, "me") is False, "NaN refused")
    zero = msg("world", "z", 10 * NS, eye)
    zero.transform.rotation.w = 0.0
    check(buf.set_transform(zero, "me") is False, "zero-length quaternion refused")
    check(buf.set_transform(msg("world", "world", 10 * NS, eye), "me") is False, "self transform")
    check(buf.set_transform(msg("", "q", 10 * NS, eye), "me") is False, "empty frame_id")
    raises(
        tf2_ros.LookupException,
        '"n" passed to lookupTransform argument source_frame does not exist. ',
        buf.lookup_transform,
        "world",
        "n",
        Time(),
    )
    # the cache keeps cache_time: older data goes, data older than that is refused
    short = tf2_ros.Buffer(cache_time=Duration(seconds=2))
    for k in range(50):
        short.set_transform(msg("world", "m", 100 * NS + k * NS // 10, eye), "me")  # 100.0 .. 104.9
    raises(
        tf2_ros.ExtrapolationException,
        "Lookup would require extrapolation into the past.  Requested time 102.500000 but the "
        "earliest data is at time 102.800000, when looking up transform from frame [m] to frame "
        "[world]",
        short.lookup_transform,
        "world",
        "m",
        Time(nanoseconds=102_500_000_000),
    )
    check(short.set_transform(msg("world", "m", 101 * NS, eye), "me") is False, "TF_OLD_DATA")
    check(short.can_transform("world", "m", Time(nanoseconds=104_000_000_000)), "recent data kept")
    # A frame sent with a second parent: stored (the newest data wins), warned once per pair
    two = tf2_ros.Buffer()
    shifted = pt.transform_from(np.eye(3), np.array([0.0, 0.0, 1.0]))
    check(two.set_transform(msg("world", "arm", 10 * NS, eye), "driver"), "first parent")
    check(two.set_transform(msg("table", "arm", 11 * NS, shifted), "calibration"), "second parent")
    check(two.set_transform(msg("table", "arm", 12 * NS, shifted), "calibration"), "again")
    arm = two.lookup_transform("table", "arm", Time())
    check(arm.transform.translation.z == 1.0, "the newest parent's transform wins")
    raises(
        tf2_ros.ConnectivityException,
        "Could not find a connection between 'world' and 'arm' because they are not part of "
        "the same tree.Tf has two or more unconnected trees.",
        two.lookup_transform,
        "world",
        "arm",
        Time(),
    )
    # ...while the past still knows the old parent (between the two: the older one holds)
    for when in (10 * NS, 10 * NS + NS // 2):
        old = two.lookup_transform("world", "arm", Time(nanoseconds=when))
        check(old.transform.translation.z == 0.0, f"arm under world at {when}")
    # a loop: tf2's walk refuses it, whichever way it is entered
    loop = tf2_ros.Buffer()
    loop.set_transform(msg("world", "l0", 10 * NS, eye), "me")
    loop.set_transform(msg("l2", "l1", 10 * NS, eye), "me")
    loop.set_transform(msg("l1", "l2", 10 * NS, eye), "me")
    loop.set_transform(msg("l1", "l3", 10 * NS, shifted), "me")
    for target, source in (("world", "l1"), ("l0", "l3")):
        try:
            loop.lookup_transform(target, source, Time(nanoseconds=10 * NS))
        except tf2_ros.LookupException as exc:
            check(
                str(exc).startswith("The tf tree is invalid because it contains a loop."), str(exc)
            )
        else:
            check(False, f"a lookup {source} -> {target} through a loop must fail")
    inside = loop.lookup_transform("l1", "l3", Time(nanoseconds=10 * NS))
    check(inside.transform.translation.z == 1.0, "a lookup below the loop still works")
    # YAML and string views of the tree
    text = buf.all_frames_as_string()
    check("Frame a exists with parent world.\n" in text, text)
    yaml_text = buf.all_frames_as_yaml()
    check("a: \n  parent: 'world'\n  broadcaster: 'me'\n" in yaml_text, yaml_text)
    check(tf2_ros.Buffer().all_frames_as_yaml() == "[]", "empty buffer YAML")
    # geometry helpers against numpy
    rot = pr.active_matrix_from_angle(2, 0.7)
    m = pt.transform_from(rot, np.array([1.0, 2.0, 3.0]))
    t = msg("world", "cam", 0, m)
    v = Vector3Stamped()
    v.vector.x = 1.0
    out = do_transform_vector3(v, t)
    check(
        np.allclose([out.vector.x, out.vector.y, out.vector.z], rot @ [1, 0, 0]),
        "vector3 rotates only",
    )
    p = PointStamped()
    p.point.x = 1.0
    out_p = do_transform_point(p, t)
    check(
        np.allclose([out_p.point.x, out_p.point.y, out_p.point.z], (m @ [1, 0, 0, 1])[:3]), "point"
    )
    ps = PoseStamped()
    ps.pose.orientation.w = 1.0
    out_pose = do_transform_pose(ps.pose, t)
    q = pr.quaternion_from_matrix(rot)
    got_q = [
        out_pose.orientation.w,
        out_pose.orientation.x,
        out_pose.orientation.y,
        out_pose.orientation.z,
    ]
    check(np.allclose(got_q, q) or np.allclose(got_q, -q), "pose orientation")
    static_buf = tf2_ros.Buffer()
    static_buf.set_transform_static(t, "me")
    ps.header.frame_id = "cam"
    out_ps = static_buf.transform(ps, "world")
    check(type(out_ps) is PoseStamped and out_ps.header.frame_id == "world", "transform(pose)")
    check(
        np.allclose(
            [out_ps.pose.position.x, out_ps.pose.position.y, out_ps.pose.position.z], [1, 2, 3]
        ),
        "pose pos",
    )


def main() -> None:
    seed = int(sys.argv[1]) if len(sys.argv) > 1 else 1
    rng = np.random.default_rng(seed)
    for _ in range(4):
        check_tree(rng)
    check_errors_and_bad_input()
    leaked = sorted(m for m in sys.modules if m.split(".")[0] in ("app", "nodes"))
    check(not leaked, f"imported project modules: {leaked}")
    print(f"OK {checks}", flush=True)


if __name__ == "__main__":
    main()
