"""Monocular visual odometry and mapping: the geometry, without ROS.

The pipeline a learner can follow, one frame at a time:

1. **Features.** Corners (Shi-Tomasi "good features to track") are detected
   in a frame and followed into the next frames with pyramidal Lucas-Kanade
   optical flow; a forward-backward check throws away tracks that do not
   come back to where they started. :func:`match_orb` shows the other classic
   way, ORB descriptors matched between two frames.
2. **Initialisation (two views).** Once the tracks have moved enough, the
   essential matrix between the first frame and the current one is estimated
   with RANSAC (:func:`relative_pose`), decomposed into a rotation and a
   unit-length translation (``cv2.recoverPose``), and the tracked corners are
   triangulated (:func:`triangulate`) into the first 3D map points. A single
   camera cannot know metric scale, so the first baseline defines the unit.
3. **Tracking.** Every later frame is located against the map with
   Perspective-n-Point (``cv2.solvePnPRansac``, then Levenberg-Marquardt
   refinement): the 3D points are known, their pixels were just tracked.
4. **Mapping.** Tracks without a 3D point are triangulated between the frame
   where they were first seen and the current one as soon as the two viewing
   rays are far enough apart; new corners are detected where the image has
   few tracks. The map grows as the camera explores.

Frames: poses are ``T_world_cam`` (optical camera frame: x right, y down,
z forward); the SLAM "world" is the first camera's frame.

:func:`umeyama_alignment` and :func:`absolute_trajectory_error` score an
estimated trajectory against ground truth up to the unknown similarity
(rotation, translation and scale).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import cv2
import numpy as np

from nodes.common.frames import invert_transform, make_transform

# --------------------------------------------------------------- two-view geometry


def match_orb(
    gray_a: np.ndarray, gray_b: np.ndarray, n_features: int = 1500, ratio: float = 0.75
) -> tuple[np.ndarray, np.ndarray]:
    """ORB keypoints matched between two images (Lowe's ratio test): (N, 2) pixels each."""
    orb = cv2.ORB.create(nfeatures=n_features)
    kp_a, des_a = orb.detectAndCompute(gray_a, None)
    kp_b, des_b = orb.detectAndCompute(gray_b, None)
    if des_a is None or des_b is None or len(kp_a) < 2 or len(kp_b) < 2:
        return np.empty((0, 2), np.float32), np.empty((0, 2), np.float32)
    matcher = cv2.BFMatcher(cv2.NORM_HAMMING)
    good = [
        pair[0]
        for pair in matcher.knnMatch(des_a, des_b, k=2)
        if len(pair) == 2 and pair[0].distance < ratio * pair[1].distance
    ]
    pts_a = np.array([kp_a[m.queryIdx].pt for m in good], np.float32).reshape(-1, 2)
    pts_b = np.array([kp_b[m.trainIdx].pt for m in good], np.float32).reshape(-1, 2)
    return pts_a, pts_b


def relative_pose(
    pts_a: np.ndarray, pts_b: np.ndarray, K: np.ndarray, threshold_px: float = 1.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Motion from view a to view b: ``(R, t, inliers)`` with ``x_b = R x_a + t``, |t| = 1.

    Essential matrix by RANSAC, then the one of its four decompositions that
    puts the points in front of both cameras. None when it cannot be found.
    """
    if len(pts_a) < 8:
        return None
    E, mask = cv2.findEssentialMat(
        pts_a, pts_b, K, method=cv2.RANSAC, prob=0.999, threshold=threshold_px
    )
    if E is None or E.shape != (3, 3):
        return None
    count, R, t, mask = cv2.recoverPose(E, pts_a, pts_b, K, mask=mask)
    if count < 8:
        return None
    return R, t.reshape(3), mask.reshape(-1).astype(bool)


def projection_matrix(K: np.ndarray, T_world_cam: np.ndarray) -> np.ndarray:
    """3x4 ``K [R | t]`` that projects world points into the camera."""
    return K @ invert_transform(T_world_cam)[:3, :]


def triangulate(
    K: np.ndarray, T_world_a: np.ndarray, T_world_b: np.ndarray, pts_a, pts_b
) -> np.ndarray:
    """World points (N, 3) seen at ``pts_a`` from pose a and ``pts_b`` from pose b (DLT)."""
    homogeneous = cv2.triangulatePoints(
        projection_matrix(K, T_world_a),
        projection_matrix(K, T_world_b),
        np.asarray(pts_a, np.float64).T,
        np.asarray(pts_b, np.float64).T,
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        return (homogeneous[:3] / homogeneous[3]).T


def project(K: np.ndarray, T_world_cam: np.ndarray, points: np.ndarray):
    """Pixels (N, 2) and depths (N,) of world points in a camera."""
    T_cam_world = invert_transform(T_world_cam)
    cam = points @ T_cam_world[:3, :3].T + T_cam_world[:3, 3]
    depth = cam[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        pixels = (cam[:, :2] / depth[:, None]) * (K[0, 0], K[1, 1]) + (K[0, 2], K[1, 2])
    return pixels, depth


def ray_angles(K: np.ndarray, T_world_a, T_world_b, pts_a, pts_b) -> np.ndarray:
    """Angle (radians) between the viewing rays of matched pixels in two posed views."""
    K_inv = np.linalg.inv(K)

    def rays(T, pts):
        homog = np.column_stack([pts, np.ones(len(pts))]) @ K_inv.T
        world = homog @ T[:3, :3].T
        return world / np.linalg.norm(world, axis=1, keepdims=True)

    cosine = np.sum(rays(T_world_a, pts_a) * rays(T_world_b, pts_b), axis=1)
    return np.arccos(np.clip(cosine, -1.0, 1.0))


# ---------------------------------------------------------------- evaluation


def umeyama_alignment(source: np.ndarray, target: np.ndarray, with_scale: bool = True):
    """Similarity ``(s, R, t)`` minimising ``|target - (s R source + t)|^2`` (Umeyama 1991)."""
    src = np.asarray(source, float)
    dst = np.asarray(target, float)
    mu_src, mu_dst = src.mean(axis=0), dst.mean(axis=0)
    src_c, dst_c = src - mu_src, dst - mu_dst
    covariance = dst_c.T @ src_c / len(src)
    U, D, Vt = np.linalg.svd(covariance)
    S = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        S[2, 2] = -1.0  # a reflection is not a rotation
    R = U @ S @ Vt
    variance = np.mean(np.sum(src_c**2, axis=1))
    scale = float(np.trace(np.diag(D) @ S) / variance) if with_scale else 1.0
    t = mu_dst - scale * R @ mu_src
    return scale, R, t


def absolute_trajectory_error(estimated: np.ndarray, truth: np.ndarray) -> dict[str, float]:
    """RMSE of camera positions after similarity alignment, also as % of path length."""
    est = np.asarray(estimated, float)
    gt = np.asarray(truth, float)
    scale, R, t = umeyama_alignment(est, gt)
    aligned = est @ R.T * scale + t
    errors = np.linalg.norm(aligned - gt, axis=1)
    rmse = float(np.sqrt(np.mean(errors**2)))
    length = float(np.sum(np.linalg.norm(np.diff(gt, axis=0), axis=1)))
    return {
        "ate_rmse": rmse,
        "ate_max": float(errors.max()),
        "path_length": length,
        "ate_percent": 100.0 * rmse / length if length > 0 else float("nan"),
        "scale": scale,
    }


# ------------------------------------------------------------ the odometry


@dataclass
class VOSettings:
    max_tracks: int = 400
    min_tracks: int = 250  # detect new corners below this many tracks
    min_corner_distance: int = 12
    corner_quality: float = 0.01
    lk_window: int = 21
    lk_levels: int = 3
    fb_max_error: float = 1.0  # forward-backward disagreement allowed, pixels
    refine_max_shift: float = 2.0  # keyframe re-match may move a track this far, pixels
    init_min_angle_deg: float = 2.0  # median ray angle needed to initialise
    init_min_points: int = 80
    triangulate_min_angle_deg: float = 1.5
    reprojection_max_px: float = 1.5
    improve_ratio: float = 1.5  # re-triangulate a point when its ray angle grew this much
    pnp_min_points: int = 15
    max_map_points: int = 200_000


@dataclass
class FrameResult:
    """What one call of :meth:`MonocularVO.process` found."""

    index: int
    pose: np.ndarray | None  # T_world_cam, None until initialised (or when lost)
    tracked: np.ndarray  # (N, 2) pixels of the live tracks
    mapped: np.ndarray  # (N,) bool: the track has a 3D point
    new_points: int
    map_size: int
    state: str  # "waiting", "initialised", "tracking", "lost"
    backfilled: dict[int, np.ndarray] = field(default_factory=dict)


class MonocularVO:
    """Visual odometry + a growing sparse map from one calibrated camera."""

    def __init__(self, K: np.ndarray, settings: VOSettings | None = None) -> None:
        self.K = np.asarray(K, float)
        self.settings = settings or VOSettings()
        self.reset()

    def reset(self) -> None:
        self.index = -1
        self.prev_gray: np.ndarray | None = None
        self.keyframes: dict[int, np.ndarray] = {}  # grey images where tracks started
        self.poses: dict[int, np.ndarray] = {}
        self.points = np.empty((0, 3), np.float64)
        self.colors = np.empty((0, 3), np.uint8)  # RGB
        self.point_angle = np.empty(0, np.float64)  # ray angle each point was triangulated at
        self.initialised = False
        self._next_uid = 0
        self._pre_init: list[tuple[int, np.ndarray, np.ndarray]] = []
        # Before initialisation every track starts in the reference frame, whose
        # pose is the identity (or, after tracking was lost, the last known pose).
        self.ref_index = 0
        self.ref_pose = np.eye(4)
        self._tracks_empty()

    def _tracks_empty(self) -> None:
        self.pts = np.empty((0, 2), np.float32)
        self.anchor_pts = np.empty((0, 2), np.float32)
        self.anchor_frame = np.empty(0, np.int64)
        self.point_id = np.empty(0, np.int64)
        self.uid = np.empty(0, np.int64)

    # -- bookkeeping -------------------------------------------------------------------
    def _keep(self, keep: np.ndarray) -> None:
        self.pts = self.pts[keep]
        self.anchor_pts = self.anchor_pts[keep]
        self.anchor_frame = self.anchor_frame[keep]
        self.point_id = self.point_id[keep]
        self.uid = self.uid[keep]

    def _add_map_points(
        self, xyz: np.ndarray, bgr: np.ndarray, pixels: np.ndarray, angles: np.ndarray
    ) -> np.ndarray:
        h, w = bgr.shape[:2]
        px = np.clip(pixels.round().astype(int), 0, (w - 1, h - 1))
        rgb = (
            bgr[px[:, 1], px[:, 0], ::-1]
            if bgr.ndim == 3
            else np.repeat(bgr[px[:, 1], px[:, 0], None], 3, axis=1)
        )
        first = len(self.points)
        self.points = np.vstack([self.points, xyz])
        self.colors = np.vstack([self.colors, rgb.astype(np.uint8)])
        self.point_angle = np.concatenate([self.point_angle, angles])
        return np.arange(first, first + len(xyz))

    def _detect(self, gray: np.ndarray) -> None:
        s = self.settings
        wanted = s.max_tracks - len(self.pts)
        if wanted <= 0:
            return
        mask = np.full(gray.shape, 255, np.uint8)
        for x, y in self.pts.astype(int):
            cv2.circle(mask, (int(x), int(y)), s.min_corner_distance, 0, -1)
        corners = cv2.goodFeaturesToTrack(
            gray, wanted, s.corner_quality, s.min_corner_distance, mask=mask, blockSize=5
        )
        if corners is None:
            return
        corners = corners.reshape(-1, 2).astype(np.float32)
        n = len(corners)
        self.keyframes[self.index] = gray
        self.pts = np.vstack([self.pts, corners])
        self.anchor_pts = np.vstack([self.anchor_pts, corners])
        self.anchor_frame = np.concatenate([self.anchor_frame, np.full(n, self.index)])
        self.point_id = np.concatenate([self.point_id, np.full(n, -1)])
        self.uid = np.concatenate([self.uid, np.arange(self._next_uid, self._next_uid + n)])
        self._next_uid += n

    def _track(self, prev_gray: np.ndarray, gray: np.ndarray) -> None:
        s = self.settings
        if len(self.pts) == 0:
            return
        params: dict[str, Any] = dict(
            winSize=(s.lk_window, s.lk_window),
            maxLevel=s.lk_levels,
            criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01),
        )
        p0 = self.pts.reshape(-1, 1, 2)
        # nextPts=None: OpenCV allocates the output; its type stubs do not allow None there.
        flow = cv2.calcOpticalFlowPyrLK
        p1, st1, _ = flow(prev_gray, gray, p0, None, **params)  # type: ignore[call-overload]
        back, st2, _ = flow(gray, prev_gray, p1, None, **params)  # type: ignore[call-overload]
        p1 = p1.reshape(-1, 2)
        fb = np.linalg.norm(back.reshape(-1, 2) - self.pts, axis=1)
        h, w = gray.shape
        inside = (p1[:, 0] >= 0) & (p1[:, 0] < w - 1) & (p1[:, 1] >= 0) & (p1[:, 1] < h - 1)
        keep = (st1.reshape(-1) == 1) & (st2.reshape(-1) == 1) & (fb < s.fb_max_error) & inside
        self.pts = p1
        self._keep(keep)
        self._refine_against_keyframes(gray, params)

    def _refine_against_keyframes(self, gray: np.ndarray, params: dict) -> None:
        """Re-match every track against the image where it started.

        Frame-to-frame flow drifts a little each frame; matching the original
        patch (starting from the frame-to-frame guess) removes that drift, and
        a track whose two answers disagree is dropped as unreliable.
        """
        s = self.settings
        keep = np.ones(len(self.pts), bool)
        refined = self.pts.copy()
        for anchor in np.unique(self.anchor_frame):
            template = self.keyframes.get(int(anchor))
            if template is None or anchor == self.index - 1:
                continue
            rows = np.flatnonzero(self.anchor_frame == anchor)
            guess = self.pts[rows].reshape(-1, 1, 2).copy()
            found, status, _ = cv2.calcOpticalFlowPyrLK(
                template,
                gray,
                self.anchor_pts[rows].reshape(-1, 1, 2),
                guess,
                flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
                **{**params, "maxLevel": 1},
            )
            found = found.reshape(-1, 2)
            moved = np.linalg.norm(found - self.pts[rows], axis=1)
            good = (status.reshape(-1) == 1) & (moved < s.refine_max_shift)
            refined[rows] = found
            keep[rows[~good]] = False
        self.pts = refined
        self._keep(keep)
        live = set(np.unique(self.anchor_frame).tolist())
        for index in [i for i in self.keyframes if i not in live]:
            del self.keyframes[index]

    # -- the stages ---------------------------------------------------------------------
    def _try_initialise(self, bgr: np.ndarray) -> bool:
        s = self.settings
        if len(self.pts) < s.init_min_points:
            return False
        found = relative_pose(self.anchor_pts, self.pts, self.K)
        if found is None:
            return False
        R, t, inliers = found
        # x_cur = R x_0 + t  is the transform cam0 -> cur; the pose is its inverse.
        T_world_0 = self.ref_pose
        T_world_cur = T_world_0 @ invert_transform(make_transform(R, t))
        xyz = triangulate(self.K, T_world_0, T_world_cur, self.anchor_pts, self.pts)
        good = inliers & self._well_triangulated(xyz, T_world_0, T_world_cur)
        angles = ray_angles(self.K, T_world_0, T_world_cur, self.anchor_pts, self.pts)
        if good.sum() < s.init_min_points:
            return False
        if np.degrees(np.median(angles[good])) < s.init_min_angle_deg:
            return False
        self.poses[self.ref_index] = T_world_0
        self.poses[self.index] = T_world_cur
        ids = self._add_map_points(xyz[good], bgr, self.pts[good], angles[good])
        self.point_id[good] = ids
        # Outliers of the essential matrix are bad tracks: drop them.
        self._keep(inliers)
        self.initialised = True
        return True

    def _well_triangulated(self, xyz, T_a, T_b, pts_a=None, pts_b=None) -> np.ndarray:
        s = self.settings
        pts_a = self.anchor_pts if pts_a is None else pts_a
        pts_b = self.pts if pts_b is None else pts_b
        ok = np.isfinite(xyz).all(axis=1)
        for T, pts in ((T_a, pts_a), (T_b, pts_b)):
            pixels, depth = project(self.K, T, np.nan_to_num(xyz))
            error = np.linalg.norm(pixels - pts, axis=1)
            ok &= (depth > 0) & (error < s.reprojection_max_px)
        return ok

    def _backfill(self) -> dict[int, np.ndarray]:
        """Locate the frames seen before initialisation against the first map."""
        found: dict[int, np.ndarray] = {}
        mapped = self.point_id >= 0
        lookup = dict(zip(self.uid[mapped].tolist(), self.point_id[mapped].tolist(), strict=True))
        for index, uids, pts in self._pre_init:
            if index in self.poses:
                continue
            rows = [i for i, u in enumerate(uids.tolist()) if u in lookup]
            if len(rows) < self.settings.pnp_min_points:
                continue
            obj = self.points[[lookup[int(uids[i])] for i in rows]]
            pose = self._solve_pnp(obj, pts[rows], None)
            if pose is not None:
                self.poses[index] = pose[0]
                found[index] = pose[0]
        self._pre_init.clear()
        return found

    def _solve_pnp(self, obj, img, guess):
        s = self.settings
        if len(obj) < s.pnp_min_points:
            return None
        kwargs: dict[str, Any] = {}
        if guess is not None:
            T_cam_world = invert_transform(guess)
            rvec, _ = cv2.Rodrigues(T_cam_world[:3, :3])
            kwargs = dict(
                rvec=rvec, tvec=T_cam_world[:3, 3].reshape(3, 1).copy(), useExtrinsicGuess=True
            )
        ok, rvec, tvec, inliers = cv2.solvePnPRansac(
            obj.astype(np.float64),
            img.astype(np.float64),
            self.K,
            None,
            iterationsCount=100,
            reprojectionError=2.0,
            confidence=0.999,
            flags=cv2.SOLVEPNP_ITERATIVE,
            **kwargs,
        )
        if not ok or inliers is None or len(inliers) < s.pnp_min_points:
            return None
        inliers = inliers.reshape(-1)
        rvec, tvec = cv2.solvePnPRefineLM(
            obj[inliers].astype(np.float64),
            img[inliers].astype(np.float64),
            self.K,
            None,
            rvec,
            tvec,
        )
        R, _ = cv2.Rodrigues(rvec)
        mask = np.zeros(len(obj), bool)
        mask[inliers] = True
        return invert_transform(make_transform(R, tvec.reshape(3))), mask

    def _locate(self) -> bool:
        mapped = np.flatnonzero(self.point_id >= 0)
        guess = self.poses.get(self.index - 1)
        found = self._solve_pnp(self.points[self.point_id[mapped]], self.pts[mapped], guess)
        if found is None:
            return False
        pose, inlier_mask = found
        self.poses[self.index] = pose
        keep = np.ones(len(self.pts), bool)
        keep[mapped[~inlier_mask]] = False
        self._keep(keep)
        return True

    def _extend_map(self, bgr: np.ndarray) -> int:
        s = self.settings
        candidates = np.flatnonzero(self.point_id < 0)
        if len(candidates) == 0 or len(self.points) >= s.max_map_points:
            return 0
        T_cur = self.poses[self.index]
        added = 0
        for anchor in np.unique(self.anchor_frame[candidates]):
            T_anchor = self.poses.get(int(anchor))
            if T_anchor is None or anchor == self.index:
                continue
            rows = candidates[self.anchor_frame[candidates] == anchor]
            pa, pb = self.anchor_pts[rows], self.pts[rows]
            wide = ray_angles(self.K, T_anchor, T_cur, pa, pb) > np.radians(
                s.triangulate_min_angle_deg
            )
            if not wide.any():
                continue
            angles = ray_angles(self.K, T_anchor, T_cur, pa, pb)[wide]
            rows, pa, pb = rows[wide], pa[wide], pb[wide]
            xyz = triangulate(self.K, T_anchor, T_cur, pa, pb)
            good = self._well_triangulated(xyz, T_anchor, T_cur, pa, pb)
            if good.any():
                ids = self._add_map_points(xyz[good], bgr, pb[good], angles[good])
                self.point_id[rows[good]] = ids
                added += int(good.sum())
            # Tracks that failed the checks were bad: forget them.
            bad = np.ones(len(self.pts), bool)
            bad[rows[~good]] = False
            self._keep(bad)
            candidates = np.flatnonzero(self.point_id < 0)
        self._improve_points()
        return added

    def _improve_points(self) -> None:
        """Re-triangulate mapped tracks once their baseline has grown.

        A point triangulated from a small angle has an uncertain depth; the
        same track seen from farther away pins it down better.
        """
        s = self.settings
        T_cur = self.poses[self.index]
        mapped = np.flatnonzero(self.point_id >= 0)
        for anchor in np.unique(self.anchor_frame[mapped]):
            T_anchor = self.poses.get(int(anchor))
            if T_anchor is None or anchor == self.index:
                continue
            rows = mapped[self.anchor_frame[mapped] == anchor]
            pa, pb = self.anchor_pts[rows], self.pts[rows]
            ids = self.point_id[rows]
            angles = ray_angles(self.K, T_anchor, T_cur, pa, pb)
            better = (angles > s.improve_ratio * self.point_angle[ids]) & (
                angles < np.radians(40.0)
            )
            if not better.any():
                continue
            rows, pa, pb, ids, angles = (
                rows[better],
                pa[better],
                pb[better],
                ids[better],
                angles[better],
            )
            xyz = triangulate(self.K, T_anchor, T_cur, pa, pb)
            good = self._well_triangulated(xyz, T_anchor, T_cur, pa, pb)
            self.points[ids[good]] = xyz[good]
            self.point_angle[ids[good]] = angles[good]

    # -- public -------------------------------------------------------------------------
    def process(self, image: np.ndarray) -> FrameResult:
        """Feed the next frame (BGR or grey); returns the pose and the live tracks."""
        bgr = image
        gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
        self.index += 1
        state, added, backfilled = "tracking", 0, {}
        if self.prev_gray is None:
            self._detect(gray)
            state = "waiting"
        else:
            self._track(self.prev_gray, gray)
            if not self.initialised:
                if self._try_initialise(bgr):
                    state = "initialised"
                    backfilled = self._backfill()
                else:
                    state = "waiting"
                    self._pre_init.append((self.index, self.uid.copy(), self.pts.copy()))
                    if len(self.pts) < self.settings.init_min_points:
                        # Too few tracks survive to ever initialise: start over from here.
                        self._start_reference(gray)
            elif self._locate():
                added = self._extend_map(bgr)
            else:
                state = "lost"
                self._lose_map(gray)
            if self.initialised and len(self.pts) < self.settings.min_tracks:
                self._detect(gray)
        self.prev_gray = gray
        mapped = self.point_id >= 0
        return FrameResult(
            index=self.index,
            pose=self.poses.get(self.index),
            tracked=self.pts.copy(),
            mapped=mapped,
            new_points=added,
            map_size=len(self.points),
            state=state,
            backfilled=backfilled,
        )

    def _start_reference(self, gray: np.ndarray) -> None:
        """Make this frame the reference of a new initialisation attempt."""
        self._tracks_empty()
        self._pre_init.clear()
        self.ref_index = self.index
        self._detect(gray)

    def _lose_map(self, gray: np.ndarray) -> None:
        """Tracking failed: keep the old map, start a new segment from the last known pose.

        A monocular restart cannot recover the old scale; the new segment
        simply continues from where the camera was last seen.
        """
        self.initialised = False
        last = max((i for i in self.poses if i < self.index), default=None)
        self.ref_pose = self.poses[last] if last is not None else np.eye(4)
        self._start_reference(gray)
