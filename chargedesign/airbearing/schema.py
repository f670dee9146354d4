"""The JSON Schema of testbed.json (``chargedesign schema testbed``): the contract's keys
required, further keys welcome (the file also carries requirements, tolerances, sources)."""

from __future__ import annotations

from typing import Any

from chargedesign.scene.keys import KEY

_NUMBER = {"type": "number"}
_NONNEG = {"type": "number", "minimum": 0}
_POSITIVE = {"type": "number", "exclusiveMinimum": 0}
_VECTOR = {"type": "array", "items": _NUMBER, "minItems": 3, "maxItems": 3}
_MATRIX = {"type": "array", "items": _VECTOR, "minItems": 3, "maxItems": 3}


def _object(properties: dict[str, Any], required: list[str] | None = None) -> dict[str, Any]:
    return {
        "type": "object",
        "properties": properties,
        "required": list(properties) if required is None else required,
        "additionalProperties": True,
    }


def _results_schema() -> dict[str, Any]:
    """testbed.json's ``results``: the start, the span, the loops' drifts, the wheels' peaks."""
    drift = _object({"I4_relative_drift": _NONNEG}, ["I4_relative_drift"])
    nominal = _object({"I4_relative_drift_median": _NONNEG, "I4_relative_drift_p95": _NONNEG})
    state = {"type": "array", "items": _NUMBER, "minItems": 6, "maxItems": 6}
    needs = {
        "torque_N_m": _NONNEG,
        "momentum_N_m_s": _NONNEG,
        "momentum_norm_N_m_s": _NONNEG,
        "momentum_bound_N_m_s": _NONNEG,
    }
    index = {"type": "integer", "minimum": 0}
    contract = {
        "initial_state": state,
        KEY.t_end_s: _POSITIVE,
        "zoh_noise_free": drift,
        "nominal": nominal,
        "wheel_momentum_max_N_m_s": _NONNEG,
        "wheel_torque_max_N_m": _NONNEG,
    }
    return _object(
        {
            **contract,
            # the largest needs over the planned motions and the motions that have them
            "wheel_needs": _object(
                {**needs, "torque_motion": index, "momentum_motion": index, "motions": index}
            ),
            # each planned motion's start (the loop's first), its needs, its largest tilt
            KEY.planned_motions: {
                "type": "array",
                "minItems": 1,
                "items": _object(
                    {
                        "initial_state": state,
                        **needs,
                        "tilt_max_deg": {"type": "number", "minimum": 0, "maximum": 180},
                        "horizon_s": _POSITIVE,
                    }
                ),
            },
            KEY.target_I4_drift: _POSITIVE,
        },
        [*contract, KEY.planned_motions, KEY.target_I4_drift],
    )


def _bearing_schema() -> dict[str, Any]:
    """testbed.json's ``bearing``: style, tilt limit, pedestal axis, keep-out cone, source."""
    cone = _object({"axis": _VECTOR, "half_angle_deg": _NONNEG, "inner_radius_m": _NONNEG})
    return _object(
        {
            "style": {"enum": ["tabletop", "umbrella", "full_sphere"]},
            KEY.tilt_limit_deg: {"type": "number", "exclusiveMinimum": 0, "maximum": 180},
            "pedestal_axis": _VECTOR,
            "keep_out": {"oneOf": [cone, {"type": "null"}]},
            "source": {"type": "string"},
        }
    )


def _requirement_schema() -> dict[str, Any]:
    return _object(
        {
            "name": {"type": "string"},
            "kind": {"enum": ["tolerance", "capacity"]},
            "required": _NUMBER,
            "best": _NUMBER,
            "unit": {"type": "string"},
            "source": {"type": "string"},
            "met": {"type": "boolean"},
        }
    )


def output_schema() -> dict[str, Any]:
    """The schema of testbed.json (draft 2020-12)."""
    results = _results_schema()
    properties = {
        "parameters": {"type": "object", "additionalProperties": _NUMBER},
        "platform": _object({"mass_kg": _POSITIVE, "inertia_kg_m2": _MATRIX, "com_m": _VECTOR}),
        "ballast": _object(
            {
                "positions": {"type": "array", "items": _VECTOR},
                "masses": {"type": "array", "items": _POSITIVE},
                "radii": {"type": "array", "items": _POSITIVE},
                "material": {"type": "string"},
                "mounts": {
                    "type": "array",
                    "items": _object(
                        {
                            "kind": {"type": "string"},
                            "material": {"type": "string"},
                            "stiffness_N_per_m": _POSITIVE,
                        }
                    ),
                },
            }
        ),
        "wheels": _object(
            {
                "axes": {"type": "array", "items": _VECTOR, "minItems": 3},
                KEY.max_torque_N_m: _POSITIVE,
                KEY.max_momentum_N_m_s: _POSITIVE,
                "positions": {"type": "array", "items": _VECTOR, "minItems": 3},
                "radii": {"type": "array", "items": _POSITIVE, "minItems": 3},
            }
        ),
        "control": _object({KEY.rate_Hz: _POSITIVE, KEY.delay_s: _NONNEG}),
        "sensors": _object(
            {
                KEY.gyro_arw_rad_per_sqrt_s: _NONNEG,
                KEY.gyro_bias_rad_per_s: _NONNEG,
                KEY.attitude_noise_rad: _NONNEG,
            }
        ),
        "disturbances": _object({KEY.imbalance_m: _NONNEG, KEY.drag_N_m_s: _NONNEG}),
        "inertia_total_kg_m2": _MATRIX,
        "results": results,
        "bearing": _bearing_schema(),
        "state_of_the_art": {"type": "array", "minItems": 1, "items": _requirement_schema()},
        "verdict": _object(
            {
                "buildable": {"type": "boolean"},
                "binding": {"type": ["string", "null"]},
                "line": {"type": "string"},
                "binding_source": _object(
                    {"key": {"type": "string"}, "checked": {"type": "boolean"}}
                ),
            }
        ),
        "actuators": {
            "type": "array",
            "minItems": 1,
            "items": _object(
                {
                    "name": {"type": "string"},
                    "kind": {"enum": ["reaction_wheel", "cmg"]},
                    "torque_N_m": _POSITIVE,
                    "momentum_N_m_s": _POSITIVE,
                    "mass_kg": _POSITIVE,
                    "power_W": {"oneOf": [_POSITIVE, {"type": "null"}]},
                    "source": {"type": "string"},
                    "checked": {"type": "boolean"},
                }
            ),
        },
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "chargedesign/schemas/testbed.schema.json",
        "title": "chargedesign testbed.json",
        "description": "An air-bearing testbed (docs/testbed.md): platform, ballast, wheels, "
        "loop, sensors, disturbances and the loop's results. Further keys are welcome.",
        **_object(properties),
    }


__all__ = ["output_schema"]
