"""3D boxes from depth: exact synthetic geometry, real Middlebury depth, and every rejection."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.box3d import (
    Box3D,
    Box3DConfig,
    Box3DResult,
    Rejection,
    RejectionReason,
    estimate_boxes_from_depth,
    estimate_boxes_from_points,
)

from .scenes import MOTORCYCLE_BOX, RgbdScene, optical_camera_pose, wall_with_box_scene

OBJECT = (200, 150, 300, 330)  # pixel columns 200..299, rows 150..329
OBJECT_DEPTH = 2.0


def expected_camera_extent(
    intrinsics: CameraIntrinsics, corners: tuple[int, int, int, int] = OBJECT, depth: float = OBJECT_DEPTH
) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form camera-frame extent of a flat rectangle filling pixel columns/rows x0..x1-1, y0..y1-1."""
    x0, y0, x1, y1 = corners
    lower = intrinsics.back_project(np.array(x0), np.array(y0), np.array(depth))
    upper = intrinsics.back_project(np.array(x1 - 1), np.array(y1 - 1), np.array(depth))
    return lower, upper


def only_box(results: list[Box3DResult]) -> Box3D:
    assert len(results) == 1 and isinstance(results[0], Box3D), results
    return results[0]


def test_object_in_front_of_a_wall_has_its_exact_extent() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    # The detection box is loose (20 px of wall on each side): the depth band must discard the wall.
    loose = BoundingBox2D.from_corners(180.0, 130.0, 320.0, 350.0)
    box = only_box(estimate_boxes_from_depth([loose], depth, intrinsics, Pose.identity()))
    lower, upper = expected_camera_extent(intrinsics)
    np.testing.assert_allclose(box.center, (lower + upper) / 2.0, atol=1e-5)
    np.testing.assert_allclose(box.size, upper - lower, atol=1e-5)
    assert box.size[2] == pytest.approx(0.0, abs=1e-6)  # a flat object facing the camera
    assert box.center_depth == pytest.approx(OBJECT_DEPTH)
    assert box.point_count == 100 * 180


def test_box_is_expressed_in_the_world_frame() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    camera_to_world = optical_camera_pose((5.0, 1.0, 1.2))
    box = only_box(estimate_boxes_from_depth([BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, camera_to_world))
    lower, upper = expected_camera_extent(intrinsics)
    # Optical (x right, y down, z forward) -> world (x forward, y left, z up) at (5, 1, 1.2).
    center_camera = (lower + upper) / 2.0
    np.testing.assert_allclose(
        box.center, [5.0 + center_camera[2], 1.0 - center_camera[0], 1.2 - center_camera[1]], atol=1e-5
    )
    size_camera = upper - lower
    np.testing.assert_allclose(box.size, [size_camera[2], size_camera[0], size_camera[1]], atol=1e-5)


def test_median_ignores_holes_noise_and_outliers() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    rng = np.random.default_rng(3)
    region = depth[150:330, 200:300]
    region += rng.normal(0.0, 0.01, region.shape).astype(np.float32)
    holes = rng.random(region.shape) < 0.3
    region[holes] = rng.choice([np.nan, 0.0, np.inf], size=int(holes.sum()))
    region[rng.random(region.shape) < 0.05] = 0.5  # flying pixels far in front of the object
    box = only_box(estimate_boxes_from_depth([BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, Pose.identity()))
    assert box.center_depth == pytest.approx(OBJECT_DEPTH, abs=0.01)
    lower, upper = expected_camera_extent(intrinsics)
    np.testing.assert_allclose(box.size[:2], (upper - lower)[:2], rtol=0.03)
    assert box.size[2] < 0.1  # noise only: the 0.5 m outliers lie outside the band


def test_depth_band_is_configurable() -> None:
    # A slanted surface: depth grows 1 cm per column across the box.
    depth, intrinsics = wall_with_box_scene(wall_depth=6.0)
    depth[150:330, 200:300] = 2.0 + 0.01 * np.arange(100, dtype=np.float32)
    box2d = BoundingBox2D.from_corners(*OBJECT)
    narrow = only_box(
        estimate_boxes_from_depth([box2d], depth, intrinsics, Pose.identity(), Box3DConfig(depth_band_half_width=0.2))
    )
    wide = only_box(
        estimate_boxes_from_depth([box2d], depth, intrinsics, Pose.identity(), Box3DConfig(depth_band_half_width=0.6))
    )
    assert narrow.size[2] == pytest.approx(0.4, abs=0.011)  # +/- 0.2 m around the 2.495 m median
    assert wide.size[2] == pytest.approx(0.99, abs=0.011)  # the whole 1 m slope


def test_mask_restricts_the_pixels() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    mask = np.zeros(depth.shape, dtype=bool)
    mask[150:330, 200:250] = True  # only the left half of the object
    box = only_box(
        estimate_boxes_from_depth(
            [BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, Pose.identity(), masks=[mask]
        )
    )
    lower, upper = expected_camera_extent(intrinsics, corners=(200, 150, 250, 330))
    np.testing.assert_allclose(box.size, upper - lower, atol=1e-5)


def test_box_partly_outside_the_image_is_clamped() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=(0, 100, 60, 200))
    box = only_box(
        estimate_boxes_from_depth(
            [BoundingBox2D.from_corners(-80.0, 100.0, 60.0, 200.0)], depth, intrinsics, Pose.identity()
        )
    )
    lower, upper = expected_camera_extent(intrinsics, corners=(0, 100, 60, 200))
    np.testing.assert_allclose(box.size, upper - lower, atol=1e-5)


def test_rejections_carry_index_and_reason_and_never_raise() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    depth[400:480, 500:640] = np.nan  # a region with no depth at all
    depth[10:20, 10:20] = np.nan
    depth[10:20, 10:20][::3, ::3] = 3.0  # 16 scattered readings, under the minimum of 20
    boxes = [
        BoundingBox2D.from_corners(*OBJECT),
        BoundingBox2D.from_corners(700.0, 10.0, 800.0, 60.0),  # right of the image
        BoundingBox2D.from_corners(10.0, -90.0, 60.0, -10.0),  # above it
        BoundingBox2D.from_corners(520.0, 410.0, 600.0, 470.0),  # no depth
        BoundingBox2D(np.nan, 100.0, 10.0, 10.0),
        BoundingBox2D(100.0, 100.0, 0.0, 10.0),  # empty
        BoundingBox2D.from_corners(10.0, 10.0, 20.0, 20.0),  # too few readings
    ]
    results = estimate_boxes_from_depth(boxes, depth, intrinsics, Pose.identity())
    assert isinstance(results[0], Box3D)
    reasons = [(result.index, result.reason) for result in results[1:]]
    assert reasons == [
        (1, RejectionReason.OUTSIDE_IMAGE),
        (2, RejectionReason.OUTSIDE_IMAGE),
        (3, RejectionReason.TOO_FEW_DEPTH_PIXELS),
        (4, RejectionReason.INVALID_BOX),
        (5, RejectionReason.INVALID_BOX),
        (6, RejectionReason.TOO_FEW_DEPTH_PIXELS),
    ]
    assert all(isinstance(result, Rejection) and result.detail for result in results[1:])


def test_scattered_depth_is_rejected_as_too_few_pixels_in_band() -> None:
    depth, intrinsics = wall_with_box_scene()
    rng = np.random.default_rng(0)
    depth[100:200, 100:200] = rng.uniform(1.0, 9.0, (100, 100))  # no surface, only scattered readings
    config = Box3DConfig(depth_band_half_width=0.01, minimum_valid_pixels=200)
    (result,) = estimate_boxes_from_depth(
        [BoundingBox2D.from_corners(100, 100, 200, 200)], depth, intrinsics, Pose.identity(), config
    )
    assert isinstance(result, Rejection) and result.reason is RejectionReason.TOO_FEW_PIXELS_IN_BAND


def test_all_nan_depth_rejects_every_detection() -> None:
    depth, intrinsics = wall_with_box_scene()
    depth[:] = np.nan
    results = estimate_boxes_from_depth([BoundingBox2D.from_corners(*OBJECT)] * 3, depth, intrinsics, Pose.identity())
    assert [result.reason for result in results] == [RejectionReason.TOO_FEW_DEPTH_PIXELS] * 3


def test_sensor_range_limits_discard_readings() -> None:
    depth, intrinsics = wall_with_box_scene(object_depth=OBJECT_DEPTH)
    config = Box3DConfig(maximum_depth=1.5)
    (result,) = estimate_boxes_from_depth(
        [BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, Pose.identity(), config
    )
    assert isinstance(result, Rejection) and result.reason is RejectionReason.TOO_FEW_DEPTH_PIXELS


def test_bad_mask_is_a_rejection_and_mask_count_mismatch_an_error() -> None:
    depth, intrinsics = wall_with_box_scene()
    box = BoundingBox2D.from_corners(*OBJECT)
    (result,) = estimate_boxes_from_depth([box], depth, intrinsics, Pose.identity(), masks=[np.ones((5, 5), bool)])
    assert result.reason is RejectionReason.INVALID_MASK
    with pytest.raises(InvalidInputError):
        estimate_boxes_from_depth([box], depth, intrinsics, Pose.identity(), masks=[])


def test_depth_of_the_wrong_size_is_an_error() -> None:
    _, intrinsics = wall_with_box_scene()
    with pytest.raises(InvalidInputError, match="does not match the camera model"):
        estimate_boxes_from_depth([], np.ones((10, 10), np.float32), intrinsics, Pose.identity())


def test_organised_cloud_gives_the_same_boxes_as_the_depth_image() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    depth[0:50, :] = np.nan
    cloud = intrinsics.back_project_image(depth)
    pose = optical_camera_pose((1.0, 2.0, 0.5))
    boxes = [
        BoundingBox2D.from_corners(180.0, 130.0, 320.0, 350.0),
        BoundingBox2D.from_corners(400.0, 10.0, 500.0, 100.0),
    ]
    from_depth = estimate_boxes_from_depth(boxes, depth, intrinsics, pose)
    from_cloud = estimate_boxes_from_points(boxes, cloud, pose)
    for a, b in zip(from_depth, from_cloud, strict=True):
        assert isinstance(a, Box3D) and isinstance(b, Box3D)
        np.testing.assert_allclose(a.center, b.center, atol=1e-5)
        np.testing.assert_allclose(a.size, b.size, atol=1e-5)
    with pytest.raises(InvalidInputError):
        estimate_boxes_from_points(boxes, depth, pose)
    with pytest.raises(InvalidInputError):
        estimate_boxes_from_points(boxes, cloud, pose, depth_axis=3)


@pytest.mark.parametrize(
    "arguments",
    [
        dict(depth_band_half_width=0.0),
        dict(depth_band_half_width=float("inf")),
        dict(central_region_fraction=0.0),
        dict(central_region_fraction=1.5),
        dict(minimum_valid_pixels=0),
        dict(maximum_median_samples=0),
        dict(minimum_depth=3.0, maximum_depth=2.0),
    ],
)
def test_invalid_config_is_rejected(arguments: dict) -> None:
    with pytest.raises(ConfigurationError):
        Box3DConfig(**arguments)


def test_motorcycle_from_middlebury_ground_truth(motorcycle_scene: RgbdScene) -> None:
    """Real depth: the motorcycle stands about 2.4 m from the camera, side on.

    Its extent is measured from the data, not assumed: it spans image columns 90-690 and rows
    75-455, which at 2.3-2.5 m is about 1.5 m across and 0.9 m high; the band (+/- 0.2 m) limits
    the depth extent to 0.4 m while the bike's nearest (headlight, 2.15 m) and farthest (rear
    light, 2.52 m) parts are 0.37 m apart.
    """
    scene = motorcycle_scene
    camera_to_world = optical_camera_pose((0.0, 0.0, 1.0))
    box = only_box(estimate_boxes_from_depth([MOTORCYCLE_BOX], scene.depth, scene.intrinsics, camera_to_world))
    distance = float(np.linalg.norm(box.center - camera_to_world.translation))
    assert 2.2 < distance < 2.7
    length, width, height = box.size  # world x is depth, y lateral, z up
    assert 1.3 < width < 2.2  # along the bike, seen side on
    assert 0.8 < height < 1.3
    assert length <= 0.4 + 1e-6  # the band's full width
    assert box.point_count > 50_000
    # The 3D centre projects back inside the 2D box, near its middle.
    pixels, _ = scene.intrinsics.project(camera_to_world.inverse().transform_points(box.center[np.newaxis]))
    x_min, y_min, x_max, y_max = MOTORCYCLE_BOX.corners
    assert x_min + 0.3 * MOTORCYCLE_BOX.width < pixels[0, 0] < x_max - 0.3 * MOTORCYCLE_BOX.width
    assert y_min + 0.3 * MOTORCYCLE_BOX.height < pixels[0, 1] < y_max - 0.3 * MOTORCYCLE_BOX.height


def test_an_object_beyond_the_range_seen_past_a_door_frame_is_rejected_not_placed_on_the_frame() -> None:
    """Most of the box has no depth (the object is too far); its in-range pixels are the frame's."""
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT, object_depth=OBJECT_DEPTH)
    x_min, y_min, x_max, y_max = OBJECT
    depth[y_min:y_max, x_min:x_max] = np.nan  # the object: beyond the sensor's range
    frame_edge = x_min + (x_max - x_min) // 5
    depth[y_min:y_max, x_min:frame_edge] = 1.2  # a door frame in front of its left fifth
    [result] = estimate_boxes_from_depth([BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, Pose.identity())
    assert isinstance(result, Rejection)
    assert result.reason is RejectionReason.DEPTH_MOSTLY_MISSING
    assert "beyond the sensor's range" in result.detail

    # With the check off, the same box is "found" on the frame: what the check is there for.
    [placed] = estimate_boxes_from_depth([BoundingBox2D.from_corners(*OBJECT)], depth, intrinsics, Pose.identity(),
                                         Box3DConfig(minimum_depth_coverage=0.0))
    assert isinstance(placed, Box3D) and placed.center_depth == pytest.approx(1.2)


def test_depth_coverage_must_be_a_fraction() -> None:
    with pytest.raises(ConfigurationError, match="minimum_depth_coverage"):
        Box3DConfig(minimum_depth_coverage=1.5)


def test_with_a_mask_a_slanted_object_is_kept_whole_and_the_wall_its_edge_catches_left_out() -> None:
    """A television seen at a slant: 1 m deeper at one end. The band would cut it to 0.4 m."""
    depth, intrinsics = wall_with_box_scene(wall_depth=6.0)
    depth[150:330, 200:300] = 2.0 + 0.01 * np.arange(100, dtype=np.float32)
    mask = np.zeros(depth.shape, dtype=bool)
    mask[150:330, 198:300] = True  # the mask's edge bleeds two columns onto the wall behind
    box2d = BoundingBox2D.from_corners(*OBJECT)
    masked = only_box(estimate_boxes_from_depth([box2d], depth, intrinsics, Pose.identity(), masks=[mask]))
    assert masked.size[2] == pytest.approx(0.99, abs=0.011)  # the whole slope, and no wall (at 6 m)
    unmasked = only_box(estimate_boxes_from_depth([box2d], depth, intrinsics, Pose.identity()))
    assert unmasked.size[2] == pytest.approx(0.4, abs=0.011)


def test_mask_depth_gap_must_be_positive() -> None:
    with pytest.raises(ConfigurationError, match="mask_depth_gap"):
        Box3DConfig(mask_depth_gap=0.0)
