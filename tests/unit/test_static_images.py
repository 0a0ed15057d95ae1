"""The course's diagrams: generated, in sync, each used by a lesson step with alt text."""

from __future__ import annotations

import base64
import importlib.util
import re
import shutil
import sys
from pathlib import Path
from xml.etree import ElementTree

import pytest

from app import PROJECT_ROOT
from app.lessons.panel import LessonsPanel, picture_html
from app.lessons.progress import ProgressStore
from app.lessons.schema import LESSONS_DIR, STATIC_DIR, LessonError, load_lesson
from app.ui.loop import UiLoop
from tests.course_data import shared_course
from tests.unit.fake_gui import FakeGui, FakeHandle, drain

COURSE = shared_course()
IMAGE_STEPS = [
    (lesson, index, step)
    for lesson in COURSE.lessons
    for index, step in enumerate(lesson.steps)
    if step.image
]
SVG = "{http://www.w3.org/2000/svg}"


def _generator():
    path = PROJECT_ROOT / "tools" / "make_diagrams.py"
    spec = importlib.util.spec_from_file_location("make_diagrams", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["make_diagrams"] = module
    spec.loader.exec_module(module)
    return module


def test_the_course_loads_and_some_steps_have_pictures():
    assert COURSE.errors == ()
    assert len({step.image for _, _, step in IMAGE_STEPS}) >= 8


def test_every_image_a_lesson_names_exists_and_has_alt_text():
    for lesson, index, step in IMAGE_STEPS:
        where = f"{lesson.id} step {index + 1}"
        assert (STATIC_DIR / step.image).is_file(), where
        assert len(step.image_alt.split()) >= 5, f"{where}: alt text too short to describe it"


def test_every_file_in_static_is_used_by_a_lesson():
    used = {step.image for _, _, step in IMAGE_STEPS}
    present = {path.name for path in STATIC_DIR.iterdir() if path.is_file()}
    assert present - used == set(), "files in static/ that no lesson step shows"


def test_the_generator_reproduces_the_committed_files_byte_for_byte(tmp_path):
    generator = _generator()
    assert generator.main([str(tmp_path)]) == 0
    made = {path.name: path.read_bytes() for path in tmp_path.iterdir()}
    committed = {path.name: path.read_bytes() for path in STATIC_DIR.glob("*.svg")}
    assert sorted(made) == sorted(committed), "run: python tools/make_diagrams.py"
    for name, data in made.items():
        assert data == committed[name], f"static/{name} is stale: run tools/make_diagrams.py"
    assert generator.render_all() == {k: v.decode("utf-8") for k, v in made.items()}


@pytest.mark.parametrize("name", sorted(p.name for p in STATIC_DIR.glob("*.svg")))
def test_each_diagram_is_accessible_svg_sized_for_the_side_panel(name):
    root = ElementTree.parse(STATIC_DIR / name).getroot()
    assert root.tag == f"{SVG}svg"
    assert root.get("role") == "img"
    title = root.find(f"{SVG}title")
    assert title is not None and title.text and len(title.text) > 10
    desc = root.find(f"{SVG}desc")
    assert desc is not None and desc.text and len(desc.text) > 40
    assert root.get("viewBox", "").startswith("0 0 400 ")
    sizes = [float(t.get("font-size", "0")) for t in root.iter(f"{SVG}text")]
    assert sizes and min(sizes) >= 12, "text smaller than 12 units is unreadable in the panel"
    assert "<script" not in (STATIC_DIR / name).read_text(encoding="utf-8")


# -- the schema ----------------------------------------------------------------


@pytest.fixture
def lesson_copy(tmp_path) -> Path:
    source = LESSONS_DIR / "05_topics"
    target = tmp_path / source.name
    shutil.copytree(source, target)
    return target


def _with_picture(directory: Path, lines: str) -> None:
    """Put ``lines`` into the first step, after its text field."""
    toml = directory / "lesson.toml"
    text = re.sub(r'^image(_alt)? = ".*"\n', "", toml.read_text(), flags=re.M)
    text = text.replace('text = "01_talker.md"\n', 'text = "01_talker.md"\n' + lines, 1)
    toml.write_text(text)


def test_a_step_with_a_picture_loads(lesson_copy):
    _with_picture(
        lesson_copy, 'image = "topic_graph.svg"\nimage_alt = "a talker and two listeners"\n'
    )
    step = load_lesson(lesson_copy).steps[0]
    assert (step.image, step.image_alt) == ("topic_graph.svg", "a talker and two listeners")


@pytest.mark.parametrize(
    "lines, message",
    [
        ('image = "topic_graph.svg"\n', r"steps\[0\]: field 'image_alt' must describe"),
        ('image = "topic_graph.svg"\nimage_alt = "  "\n', "'image_alt' must describe"),
        ('image = "nope.svg"\nimage_alt = "x y"\n', r"steps\[0\]\.image: file 'nope.svg'"),
        ('image = "../README.md"\nimage_alt = "x y"\n', r"must name a \.svg or \.png file"),
        ('image = "../static/../app/x.svg"\nimage_alt = "x"\n', "leaves static/"),
        ('image = 3\nimage_alt = "x"\n', "field 'image' must be str"),
        ('image_alt = "a picture"\n', "'image_alt' given without 'image'"),
    ],
)
def test_a_broken_picture_field_names_the_step_and_field(lesson_copy, lines, message):
    _with_picture(lesson_copy, lines)
    with pytest.raises(LessonError, match=message) as error:
        load_lesson(lesson_copy)
    assert "05_topics/lesson.toml: steps[0]" in str(error.value)


# -- the panel -------------------------------------------------------------------


def test_picture_html_inlines_the_file_and_escapes_the_alt_text():
    markup = picture_html("topic_graph.svg", 'a "talker" & <two> listeners')
    assert 'alt="a &quot;talker&quot; &amp; &lt;two&gt; listeners"' in markup
    data = re.search(r'src="data:image/svg\+xml;base64,([^"]+)"', markup)
    assert data is not None
    assert base64.b64decode(data.group(1)) == (STATIC_DIR / "topic_graph.svg").read_bytes()
    assert "width:100%" in markup


class _SideWindow:
    def add_tab(self, *_: object) -> FakeHandle:
        return FakeHandle("tab")


class _Live:
    quiz_answers: dict = {}


class _RecordingHandle(FakeHandle):
    """Notes each property the panel sets, as viser would send it to the page."""

    sent: list[str]

    def __setattr__(self, name: str, value: object) -> None:
        if "sent" in self.__dict__:
            self.sent.append(name)
        super().__setattr__(name, value)


def test_the_panel_shows_a_steps_picture_under_its_text_and_only_there(tmp_path):
    lesson = COURSE.lesson("11_lifecycle")
    assert lesson is not None
    assert lesson.steps[0].image and not lesson.steps[1].image and not lesson.steps[2].image
    progress = ProgressStore(directory=tmp_path)
    progress.set_position(lesson.id, 0)
    gui, ui = FakeGui(), UiLoop()
    picture = _RecordingHandle("html")

    plain_add_html = gui.add_html

    def add_html(content: str = "", **kwargs: object) -> FakeHandle:
        if picture in gui.handles:  # later HTML widgets (the code window) are not the picture
            return plain_add_html(content, **kwargs)
        gui.handles.append(picture)
        return picture

    gui.add_html = add_html  # type: ignore[method-assign]
    LessonsPanel(gui, ui, COURSE, _Live(), progress, _SideWindow())  # type: ignore[arg-type]
    kinds = [h.kind for h in gui.handles]
    at = gui.handles.index(picture)
    assert kinds[at - 1 : at + 2] == ["markdown", "html", "markdown"], kinds
    assert gui.handles[at - 1].content.startswith(lesson.steps[0].text.split("\n\n")[1][:40]), (
        "the picture sits right under the step text, above the command"
    )
    alt = f'alt="{lesson.steps[0].image_alt}"'
    assert alt in picture.content and picture.visible

    gui.find("button", "Next").click()
    drain(ui)
    assert picture.content == "" and picture.visible is False
    picture.__dict__["sent"] = []
    gui.find("button", "Next").click()
    drain(ui)
    assert picture.sent == [], "an unchanged (empty) picture was sent to the page again"
    gui.find("button", "Back").click()
    gui.find("button", "Back").click()
    drain(ui)
    assert alt in picture.content and picture.visible
    assert picture.sent == ["content", "visible"]
