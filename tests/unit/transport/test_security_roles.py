"""The roles of `kinema security`: what each grant opens, as the router reads it (keys only)."""

from __future__ import annotations

import zenoh

from kinema.transport.security_folder import GRANTS, ROLES, access_rules, describe_roles


def _keys_of(rules: dict, subject: str) -> set[str]:
    policy = next(p for p in rules["policies"] if subject in p["subjects"])
    by_id = {rule["id"]: rule for rule in rules["rules"]}
    return {key for rule_id in policy["rules"] for key in by_id[rule_id]["key_exprs"]}


def _reaches(keys: set[str], key: str) -> bool:
    target = zenoh.KeyExpr(key)
    return any(zenoh.KeyExpr(expr).intersects(target) for expr in keys)


GOAL_TYPE = "moveit_studio_sdk_msgs::action::dds_::DoObjectiveSequence_SendGoal_/RIHS01_x"
SEND_GOAL = f"0/do_objective/_action/send_goal/{GOAL_TYPE}"
BY_NAME = f"0/kinema/run_objective/_action/send_goal/{GOAL_TYPE}"


def test_an_operator_reaches_the_name_doors_and_no_xml_door() -> None:
    rules = access_rules(["laptop", "tablet"], 0, xml_clients=["tablet"])
    operator = _keys_of(rules, "operators")
    assert _reaches(operator, BY_NAME) and _reaches(operator, "kinema/0/objective_server/start")
    assert _reaches(
        operator, "0/execute_objective/moveit_studio_sdk_msgs::srv::dds_::ExecuteObjective_/RIHS01_x"
    )
    assert _reaches(operator, "kinema/0/objective_server/cancel")
    assert _reaches(
        operator, "0/objective_server/blackboard/kinema_msgs::msg::dds_::BlackboardSnapshot_/RIHS01_x"
    )
    assert not _reaches(operator, SEND_GOAL)
    assert not _reaches(operator, "kinema/0/objective_server/start_xml")
    assert not _reaches(
        operator, "0/edit_waypoints/moveit_studio_agent_msgs::srv::dds_::EditWaypoints_/RIHS01_x"
    )
    with_xml = _keys_of(rules, "operators_with_xml")
    assert _reaches(with_xml, SEND_GOAL) and _reaches(with_xml, "kinema/0/objective_server/start_xml")
    subjects = {s["id"]: s.get("cert_common_names") for s in rules["subjects"]}
    assert subjects["operators"] == ["laptop"] and subjects["operators_with_xml"] == ["tablet"]


def test_the_roles_read_as_sentences_naming_every_grant() -> None:
    text = "\n".join(describe_roles())
    for role, grants in ROLES.items():
        assert f"{role}:" in text
        assert all(GRANTS[grant].summary in text for grant in grants)
    assert "never inside this security folder" in text
