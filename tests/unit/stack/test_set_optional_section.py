"""``--set`` reaches every key of an optional section (issue 38): ``robot.lidar`` is None
until a key of it is set, and a wrong key names the section's real keys."""

from __future__ import annotations

import pytest

from otonav.stack import StackConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._overrides import apply_overrides

pytestmark = pytest.mark.unit


def test_set_fills_an_optional_section_key_by_key() -> None:
    config = apply_overrides(
        StackConfig(), ["robot.lidar.body=chassis", "robot.lidar.pos=[0, 0, 0.3]"]
    )
    assert config.robot.lidar is not None
    assert (config.robot.lidar.body, config.robot.lidar.pos) == ("chassis", (0.0, 0.0, 0.3))


def test_an_unknown_key_of_an_optional_section_lists_its_real_keys() -> None:
    with pytest.raises(ConfigFileError) as caught:
        apply_overrides(StackConfig(), ["robot.lidar.height=0.3"])
    assert str(caught.value) == (
        "--set robot.lidar.height: unknown key 'height'; valid keys here: site, body, pos"
    )


def test_a_key_under_a_plain_value_lists_the_sections_there() -> None:
    with pytest.raises(ConfigFileError) as caught:
        apply_overrides(StackConfig(), ["robot.model.x=1"])
    message = str(caught.value)
    assert message.startswith("--set robot.model.x: 'robot.model' is not a section;")
    assert message.endswith("valid sections: lidar, imu, frames")


def test_a_half_set_mount_is_one_line_naming_the_rule() -> None:
    with pytest.raises(ConfigFileError, match=r"robot\.lidar.*give a site, or a pos"):
        apply_overrides(StackConfig(), ["robot.lidar.body=chassis"])
