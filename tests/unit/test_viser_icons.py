"""viser's icons are read from their zip once each, however many a page has (app/viser_icons.py)."""

from __future__ import annotations

import zipfile

import pytest
import viser._icons
from viser._icons_enum import Icon, IconName

from app import viser_icons
from app.access import make_server


def test_a_page_with_more_icons_than_visers_cache_opens_the_zip_once(monkeypatch):
    opened: list[str] = []
    real_init = zipfile.ZipFile.__init__

    def counting_init(self: zipfile.ZipFile, file: object, *args: object, **kwargs: object) -> None:
        opened.append(str(file))
        real_init(self, file, *args, **kwargs)  # type: ignore[call-overload]

    with zipfile.ZipFile(viser._icons.ICONS_DIR / "tabler-icons.zip") as icons:
        names = [IconName(n.removesuffix(".svg")) for n in icons.namelist()[:48]]  # caches 32
    monkeypatch.setattr(zipfile.ZipFile, "__init__", counting_init)
    monkeypatch.setattr(viser_icons, "_SVGS", {})
    monkeypatch.setattr(viser_icons, "_ZIP", [])
    server, _ = make_server("127.0.0.1", 0, None)
    try:
        tabs = server.gui.add_tab_group()
        for name in names:  # every add_tab renders every tab's icon again
            tabs.add_tab(name, icon=name)
        for name in names[:10]:
            server.gui.add_button(f"button {name}", icon=name)
    finally:
        server.stop()
    icon_zips = [f for f in opened if f.endswith("tabler-icons.zip")]
    assert len(icon_zips) == 1, f"the icons zip was opened {len(icon_zips)} times"
    assert len(viser_icons._SVGS) == len(names)
    assert all(svg.lstrip().startswith("<svg") for svg in viser_icons._SVGS.values())


@pytest.mark.parametrize("name", ["HOME", "PLAYER_PLAY"])
def test_the_cache_returns_what_viser_reads(name):
    from viser._icons import svg_from_icon as visers_own

    icon = getattr(Icon, name)
    assert viser_icons.svg_from_icon(icon) == visers_own(icon)
