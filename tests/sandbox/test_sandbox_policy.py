"""The static allow-list: what it lets through, and how it says what it refused."""

from __future__ import annotations

import ast

import pytest

from vcage.errors import CodeRejectedError
from vcage.sandbox.policy import MAX_CHARS, check

API = ["pick_and_place", "press", "retreat", "position"]


def test_the_allowed_language_parses() -> None:
    code = ("xs = [position(n)[0] for n in ['a', 'b'] if n != 'c']\nd = {'a': 1}\nd.get('a')\n"
            "for i in range(2):\n    if i == 0 and max(xs) > 0.1:\n        press(obj='a')\n"
            "    else:\n        continue\nretreat(home=True)\n")
    assert isinstance(check(code, API), ast.Module)


def test_every_violation_is_listed_with_its_line() -> None:
    code = "x = 1\nimport os\ny = x.__class__\nz = getattr(x, 'a')\n"
    with pytest.raises(CodeRejectedError) as err:
        check(code, API)
    text = str(err.value)
    assert "line 2: import" in text
    assert "line 3: attribute '__class__'" in text
    assert "line 4: name 'getattr' is not allowed" in text


def test_identifiers_are_checked_after_normalisation() -> None:
    with pytest.raises(CodeRejectedError, match="name 'exec' is not allowed"):
        check("ｅｘｅｃ('1')\n", API)
    with pytest.raises(CodeRejectedError, match="'__class__'"):
        check("x = ().__ｃｌａｓｓ__\n", API)


def test_unknown_names_and_attributes_are_refused() -> None:
    with pytest.raises(CodeRejectedError, match="unknown name 'teleport'"):
        check("teleport(obj='a')\n", API)
    with pytest.raises(CodeRejectedError, match="attribute 'upper' is not allowed"):
        check("'a'.upper()\n", API)


def test_size_and_depth_are_bounded() -> None:
    with pytest.raises(CodeRejectedError, match="characters"):
        check("x = 1\n" * (MAX_CHARS // 6 + 1), API)
    with pytest.raises(CodeRejectedError, match="nesting depth"):
        check("x = " + "[" * 30 + "]" * 30 + "\n", API)
    with pytest.raises(CodeRejectedError, match="not valid Python"):
        check("press(obj=\n", API)


def test_a_reply_in_prose_is_not_a_program() -> None:
    with pytest.raises(CodeRejectedError):
        check("Sure! Here is the code to put the apple on the plate.", API)
