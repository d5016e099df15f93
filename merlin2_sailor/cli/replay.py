"""``sailor replay SOURCE``: the perceptual and anchoring layers offline over real recorded data.

No ROS: the core classes run directly (detector -> ByteTrack -> percept generator -> Anchoring)
over the frames of a source, and the output folder receives annotated PNGs, a video and an
anchors summary (anchors.json, anchors.md). Sources: ``motorcycle`` (scikit-image's Middlebury
frame, a sideways-sliding camera), ``sr300`` (ViSP's real SR300 RGB-D sequence, Debian
visp-images-data), ``vtest`` (OpenCV's pedestrian video, Debian opencv-doc, depth from a
ground-plane model) and ``bag PATH`` (a rosbag2 bag, MCAP or SQLite3: a robot's recording or
``sailor demo --record``'s; its recorded detections are used where it has them). The Debian
data is fetched into a cache on first use when not installed. See ``merlin2_sailor_demos.replay``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from merlin2_sailor.cli.anchoring_settings import add_settings_arguments, parameter_sources, set_parameters
from merlin2_sailor.cli.bag_replay_options import add_bag_arguments, bag_options
from merlin2_sailor.errors import ConfigurationError

SOURCES = ("motorcycle", "sr300", "vtest", "bag")
KNOWLEDGE_FILE = "knowledge.db"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "replay", help="run detection, tracking and anchoring offline over real recorded data",
        description="Replay a real-data source through the perceptual and anchoring layers (no ROS) and write "
                    "annotated frames, a video and an anchors summary.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("source", metavar="SOURCE",
                        help=f"one of {', '.join(SOURCES)}")
    parser.add_argument("path", nargs="?", default="", metavar="PATH",
                        help="bag: the rosbag2 bag (its folder, or an .mcap / .db3 file)")
    parser.add_argument("--output", default="", metavar="DIR", help="output folder (default reports/replay/SOURCE)")
    parser.add_argument("--frames", type=int, default=None, metavar="N",
                        help="frames to process (default: the source's, about a minute at most: "
                             "motorcycle 24, sr300 30, vtest 500)")
    parser.add_argument("--stride", type=int, default=1, metavar="S", help="take every S-th frame of the source")
    parser.add_argument("--first", type=int, default=0, metavar="I", help="first source frame")
    parser.add_argument("--detector", default="ssd", metavar="NAME",
                        help="detector backend: ssd (SSD-MobileNet-v2 COCO, offline) or ultralytics")
    parser.add_argument("--score-threshold", type=float, default=None, metavar="X",
                        help="detector score threshold (default: the backend's, 0.5)")
    parser.add_argument("--matcher", default=None, metavar="NAME",
                        help="anchoring matching function, rules or network (default: the parameter files')")
    parser.add_argument("--every", type=int, default=None, metavar="K",
                        help="write every K-th processed frame as PNG (default: about a dozen images)")
    parser.add_argument("--no-video", action="store_true", help="do not write the annotated video")
    parser.add_argument("--data", default="", metavar="PATH",
                        help="sr300: ViSP's castel folder; vtest: vtest.avi (default: the Debian package, "
                             "fetched into a cache if not installed)")
    vtest = parser.add_argument_group("vtest ground-plane model")
    vtest.add_argument("--camera-height", type=float, default=None, metavar="M",
                       help="camera height above the ground in metres (default 8)")
    vtest.add_argument("--camera-pitch", type=float, default=None, metavar="DEG",
                       help="camera pitch below the horizon in degrees (default 34)")
    vtest.add_argument("--field-of-view", type=float, default=None, metavar="DEG",
                       help="horizontal field of view in degrees (default 60)")
    add_bag_arguments(parser)
    add_settings_arguments(parser)
    parser.set_defaults(run=run)


def source_options(arguments: argparse.Namespace) -> dict[str, object]:
    """The source's configuration fields given on the command line (the others keep their defaults)."""
    if arguments.source == "bag":
        return bag_options(arguments)
    if arguments.path:
        raise ConfigurationError(f"the '{arguments.source}' source takes no PATH (only bag does; see --data)")
    given = {
        "data": arguments.data or None,
        "camera_height": arguments.camera_height,
        "camera_pitch": arguments.camera_pitch,
        "field_of_view": arguments.field_of_view,
    }
    return {name: value for name, value in given.items() if value is not None}


def run(arguments: argparse.Namespace) -> int:
    from merlin2_sailor.anchoring.service import AnchoringService
    from merlin2_sailor.anchoring.settings import parameter_values
    from merlin2_sailor_demos.replay.pipeline import ReplayPipeline, create_replay_detector, create_replay_tracker
    from merlin2_sailor_demos.replay.runner import ReplayOptions, format_summary, run_replay
    from merlin2_sailor_demos.replay.sources import create_source, source_class

    for option, value, smallest in (("--stride", arguments.stride, 1), ("--frames", arguments.frames, 1),
                                    ("--every", arguments.every, 1), ("--first", arguments.first, 0)):
        if value is not None and value < smallest:
            raise ConfigurationError(f"{option} must be at least {smallest}, got {value}")
    source_class(arguments.source)  # an unknown name fails here, before any data is fetched
    # The anchoring node's own settings (the same files, read the same way), offline, with what the
    # source's camera needs, then the command line's.
    parameter_files, node = parameter_sources(arguments)
    overrides = {**({"matcher": arguments.matcher} if arguments.matcher else {}), **set_parameters(arguments)}
    source = create_source(arguments.source, source_options(arguments))
    output = Path(arguments.output) if arguments.output else Path("reports") / "replay" / source.name
    knowledge = output / KNOWLEDGE_FILE
    if arguments.source == "bag":  # a robot's run: what the anchoring node would have told the knowledge base
        output.mkdir(parents=True, exist_ok=True)
        knowledge.unlink(missing_ok=True)
        overrides = {"knowledge_base": f"sqlite://{knowledge.resolve()}", **overrides}
    settings = source.anchoring_settings(*parameter_files, overrides=overrides, node=node)
    recorded = getattr(source, "uses_recorded_detections", False)
    detector = None if recorded else create_replay_detector(arguments.detector, arguments.score_threshold)
    service = AnchoringService(settings)
    pipeline = ReplayPipeline(source, detector, create_replay_tracker(source, arguments.stride), service.anchoring,
                              lock=service.lock)
    options = ReplayOptions(
        output=output, frames=arguments.frames, stride=arguments.stride, first=arguments.first,
        image_every=arguments.every, video=not arguments.no_video,
        header={"detector": "recorded" if recorded else arguments.detector,
                "score_threshold": None if recorded else arguments.score_threshold,
                "matcher": settings.matcher.name,
                "parameter_files": [str(item) if isinstance(item, Path) else item for item in parameter_files],
                "anchoring": parameter_values(settings)},
    )
    with service:  # a knowledge base, where one is written, gets its last sync when the replay ends
        report = run_replay(pipeline, options)
    print()
    print(format_summary(report))
    print(f"wrote {len(report.files)} files to {output}/ (anchors.md, anchors.json, frames/"
          + (", the video" if any(path.suffix in (".mp4", ".avi") for path in report.files) else "")
          + (f", {KNOWLEDGE_FILE}" if knowledge.is_file() else "") + ")")
    if knowledge.is_file():
        print(f"what the robot would know: sailor knowledge show --store sqlite://{knowledge}")
    return 130 if report.interrupted else 0
