"""What the page needs so that everyone can use it: contrast and names viser leaves out.

An accessibility checker (axe-core, in tests/browser/test_accessibility.py)
found, in viser's own widgets: white text on mid blue, green, red and gray
buttons (contrast 2.3-3.6, WCAG asks 4.5), gray labels on white (3.3) and
message text on dark gray (3.5), and icon-only buttons without a name (a
message's close button, the viewer's settings button), and images without alt
text (viser's image widget shows a label, not an alt). The dashboard sends
this once: darker button colours and labels in both colour schemes (CSS
variables of Mantine, viser's UI kit), and a page script that names the
unnamed buttons as they appear. The same script shows viser's "software
WebGL" notice once per browser, for a few seconds (it covered the stage).
"""

from __future__ import annotations

from app.ui.page_script import page_script

# Filled buttons (white text) and dimmed labels, each at least 4.5:1 against its background.
_CSS = (
    ":root[data-mantine-color-scheme]{"
    "--mantine-primary-color-filled:#1971c2!important;"
    "--mantine-primary-color-filled-hover:#1864ab!important;"
    "--mantine-color-blue-filled:#1971c2!important;--mantine-color-blue-filled-hover:#1864ab!important;"
    "--mantine-color-green-filled:#2b7a3b!important;"
    "--mantine-color-green-filled-hover:#236630!important;"
    "--mantine-color-red-filled:#c92a2a!important;--mantine-color-red-filled-hover:#a82323!important;"
    "--mantine-color-gray-filled:#495057!important;--mantine-color-gray-filled-hover:#343a40!important}"
    # Orange (Next while it would skip checks) keeps Mantine's own: viser's theme picks the
    # text colour from the palette (autoContrast), black on it, 7.8:1; a darker orange
    # under that black text fell to 4.05.
    ":root[data-mantine-color-scheme=light]{--mantine-color-dimmed:#5c636a!important}"
    ":root[data-mantine-color-scheme=dark]{--mantine-color-dimmed:#b1b5b9!important}"
    ".mantine-Notification-description{color:var(--mantine-color-dimmed)!important}"
    # A long button label (a quiz answer, "Stop 3 nodes left from earlier lessons: ...")
    # wraps onto more lines instead of being cut off at the column's edge.
    ".mantine-Button-root{height:auto!important;min-height:var(--button-height)}"
    ".mantine-Button-label{white-space:normal!important;overflow:visible!important;"
    "line-height:1.3;padding:5px 0}"
    # A code block wider than the column scrolls by itself, instead of widening the list
    # item it sits in and cutting that item's text off at the column's edge.
    # (Mantine's list item lays its label out in an inline flexbox: it may shrink too.)
    "pre{max-width:100%;overflow-x:auto}"
    # A command or a program's output in a lesson's text wraps instead: a scroll bar that
    # only shows on hover hid the end of a long `ros2 run ... --remap ...` line. Listings
    # (Python, CMake, XML, the code window's numbered lines) keep their lines whole.
    "pre:not(.highlight pre):not(:has(code[class*=language-python],"
    "code[class*=language-cmake],code[class*=language-xml])){white-space:pre-wrap;"
    "overflow-wrap:anywhere}"
    ".mantine-List-itemWrapper{max-width:100%}.mantine-List-itemLabel{min-width:0;max-width:100%}"
)

_NAME_BUTTONS = """
const doc = parent.document;
const nameOf = (button) => {
  if (button.matches('.mantine-Notification-closeButton')) return 'Close this message';
  if (button.querySelector('.tabler-icon-adjustments')) return 'Viewer settings';
  return '';
};
const fix = () => {
  for (const button of doc.querySelectorAll('button:not([aria-label]):not([title])')) {
    if (button.innerText.trim()) continue;
    const name = nameOf(button);
    if (name) button.setAttribute('aria-label', name);
  }
  // Back and Next on one row (the step card's last), Back left: viser stacks every widget.
  // Their boxes are the nearest siblings holding each; half the row each.
  for (const icon of doc.querySelectorAll('button svg.icon-tabler-arrow-left')) {
    const back = icon.closest('button');
    if (!back || back.__classroomRow) continue;
    let box = back;
    for (let up = 0; box && up < 6; up++, box = box.parentElement) {
      const next = box.nextElementSibling;
      if (next && next.querySelector('button svg.icon-tabler-arrow-right')) {
        for (const half of [box, next]) {
          const css = parent.getComputedStyle(half);
          const margins = parseFloat(css.marginLeft) + parseFloat(css.marginRight) || 0;
          half.style.display = 'inline-block';
          half.style.width = `calc(50% - ${margins}px)`;
          half.style.verticalAlign = 'top';
        }
        back.__classroomRow = true;
        break;
      }
    }
  }
  // viser's image widget (turtlesim's window, camera images) has a label but no alt text.
  for (const img of doc.querySelectorAll('img:not([alt])')) {
    const box = img.parentElement && img.parentElement.parentElement;
    const label = box && box.firstElementChild && box.firstElementChild.tagName === 'P'
      ? box.firstElementChild.innerText.trim() : '';
    img.setAttribute('alt', label ? `${label} (live picture)` : 'live picture');
  }
};
// viser's "software WebGL" notice (no GPU: school laptops, VMs) covered the stage's corner
// on every screen: shown once per browser and closed after a few seconds, then never again.
const WEBGL = 'Software WebGL rendering detected';
const SEEN = 'classroom.webglNoticeSeen';
const quiet = () => {
  for (const title of doc.querySelectorAll('.mantine-Notification-title')) {
    const note = title.closest('.mantine-Notification-root');
    if (!note || note.__classroomQuiet || title.innerText.trim() !== WEBGL) continue;
    note.__classroomQuiet = true;
    const close = () => {
      const button = note.querySelector('.mantine-Notification-closeButton');
      if (button) button.click();
    };
    let seen = false;
    try {
      seen = parent.localStorage.getItem(SEEN) === '1';
      parent.localStorage.setItem(SEEN, '1');
    } catch (e) { /* no storage (private mode): close it after a while each time */ }
    if (seen) {
      note.style.display = 'none';  // not even its closing animation
      close();
    } else parent.setTimeout(close, NOTICE_MS);
  }
};
const fixAll = () => { fix(); quiet(); };
if (parent.__classroomNamer) parent.__classroomNamer.disconnect();
parent.__classroomNamer = new parent.MutationObserver(fixAll);
parent.__classroomNamer.observe(doc.body, {childList: true, subtree: true});
fixAll();
"""


NOTICE_SEC = 8.0  # the WebGL notice's first (and only) showing


def page_fixes_html() -> str:
    script = _NAME_BUTTONS.replace("NOTICE_MS", str(int(NOTICE_SEC * 1000)))
    return f"<style>{_CSS}</style>" + page_script(script, "button names")
