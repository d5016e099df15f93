"""COCO class names under the TensorFlow Object Detection API's 90-id numbering.

The TensorFlow detection models (SSD-MobileNet-v2-COCO among them) number classes 1..90 after
the COCO paper's 91 categories, of which only 80 have released annotations. That leaves ten gaps
in 1..90 (12 street sign, 26 hat, 29 shoe, 30 eye glasses, 45 plate, 66 mirror, 68 window, 69 desk,
71 door, 83 blender; the eleventh, 91 hair brush, is past the end), and 0 is the background.
YOLO models number the same 80 classes 0..79 without gaps. The names are the official COCO
spellings, the ones Ultralytics publishes, so a class is called the same whichever backend saw it.
"""

from __future__ import annotations

from types import MappingProxyType

#: TensorFlow / COCO category id -> name, 80 entries with ids between 1 and 90.
COCO_TF_LABELS = MappingProxyType(
    {
        1: "person",
        2: "bicycle",
        3: "car",
        4: "motorcycle",
        5: "airplane",
        6: "bus",
        7: "train",
        8: "truck",
        9: "boat",
        10: "traffic light",
        11: "fire hydrant",
        13: "stop sign",
        14: "parking meter",
        15: "bench",
        16: "bird",
        17: "cat",
        18: "dog",
        19: "horse",
        20: "sheep",
        21: "cow",
        22: "elephant",
        23: "bear",
        24: "zebra",
        25: "giraffe",
        27: "backpack",
        28: "umbrella",
        31: "handbag",
        32: "tie",
        33: "suitcase",
        34: "frisbee",
        35: "skis",
        36: "snowboard",
        37: "sports ball",
        38: "kite",
        39: "baseball bat",
        40: "baseball glove",
        41: "skateboard",
        42: "surfboard",
        43: "tennis racket",
        44: "bottle",
        46: "wine glass",
        47: "cup",
        48: "fork",
        49: "knife",
        50: "spoon",
        51: "bowl",
        52: "banana",
        53: "apple",
        54: "sandwich",
        55: "orange",
        56: "broccoli",
        57: "carrot",
        58: "hot dog",
        59: "pizza",
        60: "donut",
        61: "cake",
        62: "chair",
        63: "couch",
        64: "potted plant",
        65: "bed",
        67: "dining table",
        70: "toilet",
        72: "tv",
        73: "laptop",
        74: "mouse",
        75: "remote",
        76: "keyboard",
        77: "cell phone",
        78: "microwave",
        79: "oven",
        80: "toaster",
        81: "sink",
        82: "refrigerator",
        84: "book",
        85: "clock",
        86: "vase",
        87: "scissors",
        88: "teddy bear",
        89: "hair drier",
        90: "toothbrush",
    }
)


def coco_tf_label(class_id: int) -> str:
    """Name of a TensorFlow COCO class id; ids the table lacks get a visible placeholder name.

    A model can emit an id of a category that was dropped from the released annotations; calling
    it ``class_12`` keeps the detection traceable instead of failing the frame.
    """
    return COCO_TF_LABELS.get(class_id, f"class_{class_id}")
