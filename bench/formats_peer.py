#!/usr/bin/env python3
"""Recording formats beside an independent implementation: rosbags (pure-Python ROS 1 / ROS 2 bag
reader and writer).

  formats_peer.py MRTMAP SCAN WORK

1. mrtmap's bags and MCAP files are read by rosbags: every message deserialises, counts match, and
   the odometry poses composed with /tf_static give the scan's trajectory.
2. rosbags writes the scan as a ROS 1 bag (bz2 and lz4 chunks) and as a ROS 2 bag (MCAP storage,
   CDR): mrtmap converts each back to the recording layout, which must equal the original.
3. Speed: reading every message of the same bag, mrtmap convert (decode and write PNGs) against
   rosbags (deserialise only); medians of 3.
"""
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image
from rosbags.rosbag1 import Reader as Reader1, Writer as Writer1
from rosbags.rosbag2 import Reader as Reader2, Writer as Writer2, StoragePlugin, CompressionMode, CompressionFormat
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

mrtmap, scan, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
work.mkdir(parents=True, exist_ok=True)
ts1 = get_typestore(Stores.ROS1_NOETIC)
# Noetic's store lacks tf2_msgs; its definition is one line.
ts1.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
ts2 = get_typestore(Stores.ROS2_HUMBLE)


def run(*args):
    r = subprocess.run([mrtmap, *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"mrtmap {' '.join(map(str, args))} failed:\n{r.stdout}{r.stderr}")
    return r.stdout


def stream(name):
    out = []
    for line in (scan / f"{name}.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        t, p = line.split()[:2]
        out.append((float(t), scan / p))
    return out


def trajectory(folder):
    rows = [l.split() for l in (folder / "trajectory.txt").read_text().splitlines() if l and not l.startswith("#")]
    return np.array([[float(x) for x in r] for r in rows])


def quat_mat(x, y, z, w):
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def iso(t, q):
    m = np.eye(4)
    m[:3, :3] = quat_mat(*q)
    m[:3, 3] = t
    return m


# 1. mrtmap writes, rosbags reads.
print("1. mrtmap writes, rosbags reads")
traj = trajectory(scan)
for ext, comp in [("bag", "bz2"), ("bag", "lz4"), ("mcap", "lz4"), ("mcap", "bz2"), ("db3", "none")]:
    label = "zstd" if (ext, comp) == ("mcap", "bz2") else comp
    f = work / f"mrtmap-{label}.{ext}"
    run("convert", scan, "--out", f, "--compression", comp)
    counts, poses, static = {}, [], {}
    if ext == "bag":
        reader, ts, des = Reader1(f), ts1, "deserialize_ros1"
    elif ext == "db3":
        # rosbag2's SQLite storage: read the tables with Python's sqlite3, deserialise with rosbags.
        import sqlite3
        reader = None
        con = sqlite3.connect(f)
        for topic, msgtype, stamp, data in con.execute(
                "SELECT t.name, t.type, m.timestamp, m.data FROM messages m JOIN topics t ON m.topic_id = t.id ORDER BY m.timestamp"):
            msg = ts2.deserialize_cdr(bytes(data), msgtype)
            counts[topic] = counts.get(topic, 0) + 1
            if topic == "/camera/odom/sample":
                p = msg.pose.pose
                poses.append((stamp * 1e-9, iso([p.position.x, p.position.y, p.position.z],
                                                [p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w])))
            if topic == "/tf_static":
                for tr in msg.transforms:
                    t, q = tr.transform.translation, tr.transform.rotation
                    static[(tr.header.frame_id, tr.child_frame_id)] = iso([t.x, t.y, t.z], [q.x, q.y, q.z, q.w])
        con.close()
    else:
        # rosbags reads MCAP inside a ROS 2 bag folder; give it one.
        d = work / f"mrtmap-{comp}-rosbag2"
        d.mkdir(exist_ok=True)
        (d / f.name).write_bytes(f.read_bytes())
        reader = None
        from mcap.reader import make_reader
        with open(d / f.name, "rb") as fh:
            r = make_reader(fh)
            for schema, channel, message in r.iter_messages():
                msgtype = schema.name.replace("/msg/", "/msg/")
                msg = ts2.deserialize_cdr(message.data, msgtype)
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
                if channel.topic == "/camera/odom/sample":
                    p = msg.pose.pose
                    poses.append((message.log_time * 1e-9, iso([p.position.x, p.position.y, p.position.z],
                                                               [p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w])))
                if channel.topic == "/tf_static":
                    for tr in msg.transforms:
                        t, q = tr.transform.translation, tr.transform.rotation
                        static[(tr.header.frame_id, tr.child_frame_id)] = iso([t.x, t.y, t.z], [q.x, q.y, q.z, q.w])
    if reader is not None:
        with reader:
            for conn, t, raw in reader.messages():
                msg = ts1.deserialize_ros1(raw, conn.msgtype)
                counts[conn.topic] = counts.get(conn.topic, 0) + 1
                if conn.topic == "/camera/odom/sample":
                    p = msg.pose.pose
                    poses.append((t * 1e-9, iso([p.position.x, p.position.y, p.position.z],
                                                [p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w])))
                if conn.topic == "/tf_static":
                    for tr in msg.transforms:
                        tt, q = tr.transform.translation, tr.transform.rotation
                        static[(tr.header.frame_id, tr.child_frame_id)] = iso([tt.x, tt.y, tt.z], [q.x, q.y, q.z, q.w])
    pose_from_depth = static[("camera_pose_frame", "camera_color_optical_frame")]
    err = 0.0
    for (t, wp), row in zip(poses, traj):
        wd = wp @ pose_from_depth
        err = max(err, float(np.abs(wd[:3, 3] - row[1:4]).max()))
    print(f"  {f.name:<22} {sum(counts.values()):6d} messages on {len(counts)} topics deserialised by rosbags;"
          f" depth {counts.get('/camera/aligned_depth_to_color/image_raw', 0)}, thermal {counts.get('/thermal/image_raw', 0)},"
          f" poses {len(poses)}; max position error through /tf_static {err:.2e} m")
    assert counts["/camera/aligned_depth_to_color/image_raw"] == len(stream("depth"))
    assert counts["/thermal/image_raw"] == len(stream("thermal"))
    assert len(poses) == len(traj) and err < 1e-6

# 2. rosbags writes, mrtmap reads.
print("2. rosbags writes, mrtmap reads")
import tomllib
rig = tomllib.loads((scan / "rig.toml").read_text())


def msgs(ts, ros1):
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    Img = ts.types["sensor_msgs/msg/Image"]
    Info = ts.types["sensor_msgs/msg/CameraInfo"]
    Roi = ts.types["sensor_msgs/msg/RegionOfInterest"]
    Odom = ts.types["nav_msgs/msg/Odometry"]
    PoseCov = ts.types["geometry_msgs/msg/PoseWithCovariance"]
    TwistCov = ts.types["geometry_msgs/msg/TwistWithCovariance"]
    Twist = ts.types["geometry_msgs/msg/Twist"]
    Pose = ts.types["geometry_msgs/msg/Pose"]
    Point = ts.types["geometry_msgs/msg/Point"]
    Quat = ts.types["geometry_msgs/msg/Quaternion"]
    Vec3 = ts.types["geometry_msgs/msg/Vector3"]
    TF = ts.types["tf2_msgs/msg/TFMessage"]
    TS = ts.types["geometry_msgs/msg/TransformStamped"]
    Tr = ts.types["geometry_msgs/msg/Transform"]

    def hdr(t, frame):
        s = int(t)
        stamp = Time(sec=s, nanosec=int(round((t - s) * 1e9)))
        return Header(seq=0, stamp=stamp, frame_id=frame) if ros1 else Header(stamp=stamp, frame_id=frame)

    def img(t, frame, a, enc):
        return Img(header=hdr(t, frame), height=a.shape[0], width=a.shape[1], encoding=enc, is_bigendian=0,
                   step=a.shape[1] * 2, data=np.frombuffer(a.astype("<u2").tobytes(), dtype=np.uint8))

    def info(t, frame, c):
        d = c.get("distortion", [0.0] * 5)
        k = [c["fx"], 0, c["cx"], 0, c["fy"], c["cy"], 0, 0, 1]
        kw = dict(header=hdr(t, frame), height=c["height"], width=c["width"], distortion_model="plumb_bob",
                  binning_x=0, binning_y=0, roi=Roi(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))
        if ros1:
            kw.update(D=np.array(d, float), K=np.array(k, float), R=np.eye(3).ravel(), P=np.zeros(12))
        else:
            kw.update(d=np.array(d, float), k=np.array(k, float), r=np.eye(3).ravel(), p=np.zeros(12))
        return Info(**kw)

    def tr(m):
        q = quat_from(m[:3, :3])
        return Tr(translation=Vec3(x=m[0, 3], y=m[1, 3], z=m[2, 3]), rotation=Quat(x=q[0], y=q[1], z=q[2], w=q[3]))

    def odom(t, m):
        q = quat_from(m[:3, :3])
        p = Pose(position=Point(x=m[0, 3], y=m[1, 3], z=m[2, 3]), orientation=Quat(x=q[0], y=q[1], z=q[2], w=q[3]))
        z = Vec3(x=0.0, y=0.0, z=0.0)
        return Odom(header=hdr(t, "odom"), child_frame_id="base_link", pose=PoseCov(pose=p, covariance=np.zeros(36)),
                    twist=TwistCov(twist=Twist(linear=z, angular=z), covariance=np.zeros(36)))

    def tf(t, parent, child, m):
        return TF(transforms=[TS(header=hdr(t, parent), child_frame_id=child, transform=tr(m))])

    return img, info, odom, tf


def quat_from(r):
    w = np.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2
    y = np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2
    z = np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2
    x = np.copysign(x, r[2, 1] - r[1, 2])
    y = np.copysign(y, r[0, 2] - r[2, 0])
    z = np.copysign(z, r[1, 0] - r[0, 1])
    return [x, y, z, w]


dft = rig["thermal"]["depth_from_thermal"]
depth_from_thermal = iso(dft["translation"], dft["rotation_xyzw"])
base_from_depth = iso([0.1, 0.0, 0.05], [-0.5, 0.5, -0.5, 0.5])
t0 = traj[0, 0]


def write_all(write, ts, ros1):
    img, info, odom, tf = msgs(ts, ros1)
    T = "tf2_msgs/msg/TFMessage"
    write("/tf_static", T, t0, tf(t0, "base_link", "cam", base_from_depth))
    write("/tf_static", T, t0, tf(t0, "cam", "lepton", depth_from_thermal))
    write("/cam/aligned_depth_to_color/camera_info", "sensor_msgs/msg/CameraInfo", t0, info(t0, "cam", rig["depth"]))
    write("/lepton/camera_info", "sensor_msgs/msg/CameraInfo", t0, info(t0, "lepton", rig["thermal"]))
    items = [(t, "d", p) for t, p in stream("depth")] + [(t, "t", p) for t, p in stream("thermal")]
    items += [(row[0], "p", row) for row in traj]
    for t, kind, x in sorted(items, key=lambda i: i[0]):
        if kind == "d":
            write("/cam/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image", t, img(t, "cam", np.array(Image.open(x)), "16UC1"))
        elif kind == "t":
            write("/lepton/image_raw", "sensor_msgs/msg/Image", t, img(t, "lepton", np.array(Image.open(x)), "mono16"))
        else:
            wd = iso(x[1:4], x[4:8])
            write("/odom", "nav_msgs/msg/Odometry", t, odom(t, wd @ np.linalg.inv(base_from_depth)))


def compare(folder):
    a_d, b_d = stream("depth"), [(float(l.split()[0]), folder / l.split()[1]) for l in (folder / "depth.txt").read_text().splitlines() if l and not l.startswith("#")]
    assert len(a_d) == len(b_d)
    same = all(np.array_equal(np.array(Image.open(x)), np.array(Image.open(y))) for (_, x), (_, y) in zip(a_d, b_d))
    tb = trajectory(folder)
    err = float(np.abs(tb[:, 1:4] - traj[:, 1:4]).max())
    return same, err


def fill(w, ts, ros1):
    """Writes the scan's messages with a rosbags writer (ROS 1 or ROS 2)."""
    conns = {}

    def write(topic, typ, t, msg):
        if topic not in conns:
            conns[topic] = w.add_connection(topic, typ, typestore=ts)
        data = ts.serialize_ros1(msg, typ) if ros1 else ts.serialize_cdr(msg, typ)
        w.write(conns[topic], int(round(t * 1e9)), data)

    with w:
        write_all(write, ts, ros1)


def check(src, label):
    """mrtmap converts what rosbags wrote; its frames and poses must be the scan's."""
    out = work / f"from-{src.name.replace('.', '-')}"
    run("convert", src, "--out", out)
    same, err = compare(out)
    print(f"  {label} → mrtmap convert: depth frames identical {same}, max position error {err:.2e} m")
    assert same and err < 1e-6


for comp in ["bz2", "lz4"]:
    f = work / f"rosbags-{comp}.bag"
    f.unlink(missing_ok=True)
    w = Writer1(f)
    w.set_compression(Writer1.CompressionFormat.BZ2 if comp == "bz2" else Writer1.CompressionFormat.LZ4)
    fill(w, ts1, True)
    check(f, f"{f.name:<30}")

for storage, compress in [("mcap", False), ("mcap", True), ("sqlite3", False), ("sqlite3", True)]:
    d = work / f"rosbags-rosbag2-{storage}{'-zstd' if compress else ''}"
    if d.exists():
        import shutil
        shutil.rmtree(d)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    w = Writer2(d, version=8, storage_plugin=plugin)
    if compress:
        # Each message zstd-compressed on its own (rosbag2's compression_mode: message).
        w.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    fill(w, ts2, False)
    check(d, f"{d.name:<30} (ROS 2 bag folder, {storage} storage{', zstd per message' if compress else ''}, CDR)")

# 3. Speed.
print("3. reading every message (median of 3)")
def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def rosbags_read_all(reader, deserialize):
    """rosbags deserialising every message; the count."""
    n = 0
    with reader as r:
        for conn, _, raw in r.messages():
            deserialize(raw, conn.msgtype)
            n += 1
    return n


f = work / "mrtmap-lz4.bag"
ours, survey, theirs = [], [], []
for _ in range(3):
    ours.append(timed(lambda: run("convert", f, "--out", work / "speed"))[0])
    survey.append(timed(lambda: run("inspect", f))[0])
    dt, n = timed(lambda: rosbags_read_all(Reader1(f), ts1.deserialize_ros1))
    theirs.append(dt)
o, sv, th = statistics.median(ours), statistics.median(survey), statistics.median(theirs)
size = f.stat().st_size / 1e6
print(f"  {f.name} ({size:.1f} MB, {n} messages): rosbags deserialise every message {th:.2f} s;"
      f" mrtmap inspect (decompress + decode every message) {sv:.2f} s, {th / sv:.1f}x rosbags' speed;"
      f" mrtmap convert (also decode images, write the PNG folder) {o:.2f} s")

d = work / "rosbags-rosbag2-sqlite3"
ours, theirs = [], []
for _ in range(3):
    ours.append(timed(lambda: run("inspect", d))[0])
    dt, n = timed(lambda: rosbags_read_all(Reader2(d), ts2.deserialize_cdr))
    theirs.append(dt)
o, th = statistics.median(ours), statistics.median(theirs)
size = sum(p.stat().st_size for p in d.glob("*.db3")) / 1e6
print(f"  {d.name} (ROS 2 SQLite storage, {size:.1f} MB, {n} messages): rosbags deserialise every message {th:.2f} s;"
      f" mrtmap inspect {o:.2f} s, {th / o:.1f}x rosbags' speed")
