"""Declare ROS parameters with descriptors, so ``ros2 param describe`` documents every one.

Each parameter is declared with its description, its type (inferred from the default), an
optional numeric range, and whether it may change at run time. The same descriptions are kept in
config/*.yaml, where users read them.
"""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter

from merlin2_sailor.errors import ConfigurationError


def declare_parameter(
    node: Node,
    name: str,
    default: Any,
    description: str,
    minimum: float | None = None,
    maximum: float | None = None,
    read_only: bool = True,
) -> Any:
    """Declare ``name`` with a descriptor and return its value (the default when not overridden).

    Values outside [minimum, maximum] are refused by rclpy at start-up, with the range in the
    message, instead of surfacing later as strange behaviour.
    """
    descriptor = ParameterDescriptor(
        name=name,
        description=description,
        read_only=read_only,
        type=Parameter.Type.from_parameter_value(default).value,
    )
    if minimum is not None or maximum is not None:
        low = minimum if minimum is not None else -1e300
        high = maximum if maximum is not None else 1e300
        if isinstance(default, float):
            descriptor.floating_point_range = [FloatingPointRange(from_value=float(low), to_value=float(high))]
        elif isinstance(default, int) and not isinstance(default, bool):
            descriptor.integer_range = [IntegerRange(from_value=int(low), to_value=int(high), step=1)]
    try:
        return node.declare_parameter(name, default, descriptor).value
    except Exception as error:  # rclpy raises several exception types for invalid values
        raise ConfigurationError(f"parameter '{name}': {error}") from error
