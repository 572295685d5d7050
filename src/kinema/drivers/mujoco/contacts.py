"""What the robot touches: contacts between the robot's bodies and the rest of the scene.

A trajectory that ends off its goal because something is in the way (a block left where the fingers go
down, the tray's wall) reads as joints "off by" a few hundredths of a radian; naming what the robot
touches at that moment says why.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np


def robot_bodies(model: Any, joint_names: list[str]) -> np.ndarray:
    """A mask over the model's bodies: True for the bodies the joints move (each joint's body and
    everything attached below it), that is, the robot."""
    moved = np.zeros(model.nbody, dtype=bool)
    for name in joint_names:
        moved[int(model.joint(name).bodyid[0])] = True
    parents = model.body_parentid
    # Parents come before their children in MuJoCo's body order.
    for body in range(1, model.nbody):
        if not moved[body] and moved[parents[body]]:
            moved[body] = True
    return moved


def contact_reporter(model: Any, joint_names: list[str]) -> Callable[[Any], list[str]]:
    """A function of the simulation state that names what the robot (moved by ``joint_names``) touches:
    ``"cube (robotiq_85_left_finger_tip_link)"``, one entry per touched thing, robot parts in order.

    A touched body is named by its name; the world body's geoms (a table modelled in the world) by the
    geom's name."""
    robot = robot_bodies(model, joint_names)
    geom_body = model.geom_bodyid

    def thing(geom: int) -> str:
        body = int(geom_body[geom])
        if body == 0:
            return model.geom(geom).name or "the world"
        return model.body(body).name or f"body {body}"

    def touching(data: Any) -> list[str]:
        touched: dict[str, list[str]] = {}
        for index in range(int(data.ncon)):
            contact = data.contact[index]
            first, second = int(contact.geom1), int(contact.geom2)
            first_robot, second_robot = robot[geom_body[first]], robot[geom_body[second]]
            if first_robot == second_robot:
                continue  # the robot touching itself, or two other things touching each other
            part, other = (first, second) if first_robot else (second, first)
            parts = touched.setdefault(thing(other), [])
            name = model.body(int(geom_body[part])).name
            if name not in parts:
                parts.append(name)
        return [f"{other} ({', '.join(parts)})" for other, parts in touched.items()]

    return touching
