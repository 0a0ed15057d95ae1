"""The teacher's page as a JupyterHub service: the whole class, behind the hub's OAuth.

JupyterHub starts it (``python -m app.hub.teacher_service``, registered in
deploy/jupyterhub_config.py) and proxies ``/services/classroom-teacher/`` to
it. Two kinds of callers:

- Learners' dashboards POST their progress to ``api/progress`` with their
  own hub API token (``JUPYTERHUB_API_TOKEN`` of their single-user server).
  The hub tells us whose token it is; a report about anyone else is refused
  (403, saying whose token it was), so nobody can write another learner's
  row. The answer carries the teacher's messages and the reveal setting, so
  nothing needs multicast between pods.
- Teachers open the page in a browser and log in with the hub's OAuth. Only
  users the hub grants ``access:services!service=classroom-teacher`` get in:
  admins, and the teachers' group through the role in the config.

All state lives on tornado's one thread: no locks. Rows, stuck marks, the
exercises across the class and the CSV are those of ``classroom``'s teacher
page (app.teacher.record).

With ``CLASSROOM_LTI_URL`` set, the service is also the LTI 1.3 tool an LMS
launches (app/hub/lti_service.py): its login, launch, deep-linking and JWKS
addresses are under ``lti/``, it holds the tool's private key and the score
outbox in ``CLASSROOM_LTI_DIR``, and a report that shows a finished lesson or a
passed exercise of a learner who came from the LMS sends that grade back. The
teacher's page then shows each LMS learner's name beside their ``lti-`` hub
name, and links to the gradebook (``gradebook``, app/hub/lti_gradebook.py):
what was sent to the LMS, what waits in the outbox, and a Retry button.
"""

from __future__ import annotations

import csv
import html
import io
import json
import logging
import os
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any, NoReturn
from urllib.parse import urlsplit

from tornado import ioloop, web

from app.hub.hub_api import HubRefused, header_token
from app.hub.service_auth import (
    HubLoginRequired,
    OAuthCallbackHandler,
    ServiceAuth,
    ServiceSettings,
)
from app.teacher.http_report import ReportError, from_json
from app.teacher.record import (
    COLUMNS,
    MAX_NOTICE,
    LearnerRecord,
    StuckRule,
    checks_text,
    class_exercises,
    mistake_words,
    table,
    to_csv,
)

if TYPE_CHECKING:  # LTI needs PyJWT, which only a deployment with LTI installs
    from typing import TypedDict

    from app.hub.lti_service import LtiService

    class Notice(TypedDict):
        """A teacher's message, as the dashboards' progress reports get it back."""

        id: int
        to: str  # a learner's key, or "" for everyone
        text: str
        stamp: float


log = logging.getLogger(__name__)

SERVICE_NAME = "classroom-teacher"
SITE = "hub"  # the "site" of every row: the hub vouches for the learner's name
MAX_NOTICES = 50


class ClassState:
    """Everyone's latest record, the teacher's messages and the class settings."""

    def __init__(self) -> None:
        self.records: dict[str, LearnerRecord] = {}
        self.notices: list[Notice] = []
        self.reveal_after = 0  # 0: each exercise's own number
        self.rule = StuckRule()
        self.reports = 0
        self.refused = 0
        # Notice ids restart with the service: a dashboard that sees a new epoch asks anew.
        self.epoch = os.urandom(8).hex()

    def notices_for(self, learner_key: str, since: int) -> list[Notice]:
        return [n for n in self.notices if n["id"] > since and n["to"] in ("", learner_key)]

    def add_notice(self, to: str, text: str) -> Notice:
        notice: Notice = {
            "id": (self.notices[-1]["id"] + 1) if self.notices else 1,
            "to": to,
            "text": text,
            "stamp": time.time(),
        }
        self.notices = [*self.notices, notice][-MAX_NOTICES:]
        return notice


class _Base(web.RequestHandler):
    def initialize(self, state: ClassState) -> None:
        self.state = state

    def write_error(self, status_code: int, **kwargs: Any) -> None:
        reason = self._reason
        error = kwargs.get("exc_info", (None, None, None))[1]
        if isinstance(error, web.HTTPError) and error.log_message:
            reason = error.log_message
        self.set_header("Content-Type", "application/json")
        self.finish(json.dumps({"status": status_code, "error": reason}))


class ProgressReportHandler(_Base):
    """``POST api/progress``: one learner's record, sent with that learner's hub token."""

    def check_xsrf_cookie(self) -> None:  # a token in a header, never a browser cookie
        return

    async def post(self) -> None:
        hub_auth: ServiceAuth = self.settings["service_auth"]
        token = header_token(self.request.headers.get("Authorization", ""))
        if not token:
            self._refuse(401, "send your hub API token: Authorization: token <token>")
        try:
            user = await hub_auth.user_for_token(token)
        except HubRefused as error:
            raise web.HTTPError(
                502, f"could not ask the hub whose token this is: {error}"
            ) from None
        if not user or user.get("kind", "user") != "user":
            self._refuse(403, "the hub knows no user with this token")
        try:
            record = from_json(self.request.body, received_at=time.time())
        except ReportError as error:
            self._refuse(400, str(error))
        name = user["name"]
        if record.learner != name:
            self._refuse(
                403,
                f"this token is {name}'s: it cannot report progress for {record.learner!r}",
            )
        record = replace(record, site=SITE)
        self.state.records[record.key] = record
        self.state.reports += 1
        lti: LtiService | None = self.settings.get("lti")
        if lti is not None:
            try:
                lti.on_record(record)  # a finished lesson or passed exercise: a grade for the LMS
            except Exception:  # the report itself is accepted whatever grading does
                log.exception("LTI: queueing %s's score failed", name)
        since = _int_arg(self.get_argument("since", "0"))
        self.finish(
            {
                "accepted": record.key,
                "epoch": self.state.epoch,
                "notices": self.state.notices_for(record.key, since),
                "reveal_after": self.state.reveal_after,
            }
        )

    def _refuse(self, status: int, reason: str) -> NoReturn:
        self.state.refused += 1
        raise web.HTTPError(status, reason)


def _int_arg(text: str) -> int:
    try:
        return max(0, int(text))
    except ValueError:
        raise web.HTTPError(400, "since must be a whole number") from None


TeacherAuth = HubLoginRequired  # the hub's OAuth; only users granted this service get in


class _TeacherBase(TeacherAuth, _Base):
    """Pages for teachers: the hub's OAuth, and only users granted this service."""


class PageHandler(_TeacherBase):
    @web.authenticated
    def get(self) -> None:
        user = self.current_user
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store")
        lti = self.settings.get("lti")
        self.finish(
            PAGE.replace("{{xsrf}}", html.escape(self.xsrf_token.decode()))
            .replace("{{teacher}}", html.escape(user["name"]))
            .replace("{{gradebook}}", GRADEBOOK_LINK if lti is not None else "")
            .replace("{{columns}}", "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS))
            .replace("{{max_notice}}", str(MAX_NOTICE))
        )


class TableHandler(_TeacherBase):
    @web.authenticated
    def get(self) -> None:
        records = list(self.state.records.values())
        rows = table(records, self.state.rule)
        names = _lms_names(self.settings.get("lti"), records)
        self.set_header("Cache-Control", "no-store")
        self.finish(
            {
                "columns": COLUMNS,
                "rows": rows,
                "exercises": class_exercises(records, names),
                "keys": sorted(r.key for r in records),
                "names": names,
                "reports": self.state.reports,
                "refused": self.state.refused,
                "reveal_after": self.state.reveal_after,
            }
        )


class CsvHandler(_TeacherBase):
    @web.authenticated
    def get(self) -> None:
        self.set_header("Content-Type", "text/csv; charset=utf-8")
        self.set_header("Content-Disposition", 'attachment; filename="classroom-progress.csv"')
        text = to_csv(self.state.records.values(), self.state.rule)
        lti = self.settings.get("lti")
        if lti is not None:  # the LMS's names, last: the other columns keep their places
            text = _with_lms_names(text, lti.lms_names())
        self.finish(text)


def _lms_names(lti: LtiService | None, records: list[LearnerRecord]) -> dict[str, str]:
    """The LMS's name of each learner in ``records`` who came from the LMS, by hub name."""
    if lti is None:
        return {}
    known = lti.lms_names()
    return {r.learner: known[r.learner] for r in records if r.learner in known}


def _with_lms_names(text: str, names: dict[str, str]) -> str:
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        return text
    learner = rows[0].index("learner")
    out = io.StringIO()
    writer = csv.writer(out)
    writer.writerow([*rows[0], "lms_name"])
    for row in rows[1:]:
        writer.writerow([*row, names.get(row[learner], "")])
    return out.getvalue()


class LearnerHandler(_TeacherBase):
    """One learner's detail (their code and last error), as data the page shows as text."""

    @web.authenticated
    def get(self) -> None:
        key = self.get_argument("key", "")
        record = self.state.records.get(key)
        if record is None:
            raise web.HTTPError(404, f"no learner {key!r} has reported yet")
        self.finish(
            {
                "key": record.key,
                "where": f"Lesson {record.unit} · {record.lesson_title} · step "
                f"{record.step}/{record.steps}: {record.step_title}",
                "checks": checks_text(record),
                "reasons": [
                    f"{state}: {reason}"
                    for state, reason in zip(
                        record.check_states, record.check_reasons, strict=False
                    )
                ],
                "exercise": record.exercise,
                "passed": record.exercise_passed_here,
                "mistake": mistake_words(record.exercise_mistake),
                "code": record.code_excerpt,
                "last_error": record.last_error,
            }
        )


class NoticeHandler(_TeacherBase):
    @web.authenticated
    def post(self) -> None:
        body = _json_body(self.request.body)
        to, text = body.get("to", ""), str(body.get("text", "")).strip()
        if not isinstance(to, str) or (to and to not in self.state.records):
            raise web.HTTPError(400, f"no learner {to!r} in this class")
        if not text or len(text) > MAX_NOTICE:
            raise web.HTTPError(400, f"a message needs 1-{MAX_NOTICE} characters")
        self.finish({"sent": self.state.add_notice(to, text)})


class SettingsHandler(_TeacherBase):
    @web.authenticated
    def post(self) -> None:
        body = _json_body(self.request.body)
        value = body.get("reveal_after")
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 100:
            raise web.HTTPError(400, "reveal_after must be a whole number from 0 to 100")
        self.state.reveal_after = value
        self.finish({"reveal_after": value})


def _json_body(body: bytes) -> dict[str, object]:
    try:
        data = json.loads(body or b"{}")
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise web.HTTPError(400, "the body must be a JSON object") from None
    if not isinstance(data, dict):
        raise web.HTTPError(400, "the body must be a JSON object")
    return data


def _under(prefix: str, path: str) -> str:
    return prefix.rstrip("/") + "/" + path


def make_app(
    prefix: str,
    state: ClassState | None = None,
    *,
    auth: ServiceAuth | None = None,
    lti: LtiService | None = None,
) -> web.Application:
    """The service's tornado app. ``auth`` asks the hub whose token a report or a teacher's
    browser carries (the service's environment's hub, unless a test points it at its own);
    ``lti`` serves LTI, sends grades and the gradebook (None: off)."""
    state = state or ClassState()
    args: dict[str, object] = {"state": state}
    routes: list[
        tuple[str, type[web.RequestHandler]]
        | tuple[str, type[web.RequestHandler], dict[str, object]]
    ] = [
        (prefix, PageHandler, args),
        (_under(prefix, "progress.json"), TableHandler, args),
        (_under(prefix, "progress.csv"), CsvHandler, args),
        (_under(prefix, "learner.json"), LearnerHandler, args),
        (_under(prefix, "notice"), NoticeHandler, args),
        (_under(prefix, "settings"), SettingsHandler, args),
        (_under(prefix, "api/progress"), ProgressReportHandler, args),
        (_under(prefix, "oauth_callback"), OAuthCallbackHandler),
    ]
    if lti is not None:
        from app.hub.lti_gradebook import gradebook_routes

        routes += lti.routes(prefix)
        routes += gradebook_routes(prefix, lti, TeacherAuth, back=("./", "The class"))
    return web.Application(
        routes,
        # A fresh secret per start: a restarted service only sends teachers round the hub again.
        cookie_secret=os.urandom(32),
        service_auth=auth
        if auth is not None
        else ServiceAuth(ServiceSettings.from_env(SERVICE_NAME)),
        xsrf_cookies=True,
        xsrf_cookie_kwargs={"path": prefix},  # never the hub's own _xsrf, nor a learner's
        lti=lti,
    )


def _lti_from_environment(prefix: str) -> LtiService | None:
    if not os.environ.get("CLASSROOM_LTI_URL", "").strip():
        log.info("LTI is off: set CLASSROOM_LTI_URL to serve LMS launches and send grades")
        return None
    from app.hub.lti_service import from_environment

    return from_environment(prefix)


def main() -> None:
    logging.basicConfig(level=logging.INFO)
    prefix = os.environ.get("JUPYTERHUB_SERVICE_PREFIX", f"/services/{SERVICE_NAME}/")
    where = urlsplit(os.environ.get("JUPYTERHUB_SERVICE_URL", "http://127.0.0.1:10101"))
    lti = _lti_from_environment(prefix)
    app = make_app(prefix, lti=lti)
    app.listen(where.port or 80, where.hostname or "127.0.0.1", xheaders=True)
    log.info("classroom teacher service on %s under %s", where.geturl(), prefix)
    loop = ioloop.IOLoop.current()
    if lti is not None:
        loop.add_callback(lti.start)  # sends what a previous run left in the outbox
    try:
        loop.start()
    except KeyboardInterrupt:  # the hub stops its services with SIGINT
        log.info("classroom teacher service stopped")
    finally:
        if lti is not None:
            lti.stop()


GRADEBOOK_LINK = ' · <a href="gradebook">Grades sent to the LMS (gradebook)</a>'

PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><title>ROS 2 Classroom: teacher</title>
<style>
body{font-family:system-ui,sans-serif;margin:1.2em}table{border-collapse:collapse}
td,th{border:1px solid #ccc;padding:.25em .5em;text-align:left;font-size:.9em}
pre{background:#f4f4f4;padding:.5em;max-height:24em;overflow:auto}
.stuck{color:#a40}section{margin:1em 0}
</style></head><body>
<h2>ROS 2 Classroom: teacher's view</h2>
<p>Signed in through the hub as <b>{{teacher}}</b> ·
<a href="progress.csv">Download the class's progress (CSV)</a>{{gradebook}} ·
<span id="summary"></span></p>
<table id="class"><thead><tr>{{columns}}</tr></thead><tbody></tbody></table>
<section><h3>Exercises across the class</h3><ul id="exercises"></ul></section>
<section><label>Learner <select id="learner"><option value="">(choose a learner)</option>
</select></label><div id="detail"></div></section>
<section><h3>Message to learners</h3>
<label>To <select id="to"><option value="">everyone</option></select></label>
<input id="text" size="60" maxlength="{{max_notice}}"> <button id="send">Send</button>
<span id="sent"></span></section>
<section><h3>Class settings</h3>
<label>Solution after N failed checks (0: each exercise's own)
<input id="reveal" type="number" min="0" max="100" value="0"></label>
<button id="apply">Apply to every learner</button> <span id="applied"></span></section>
<script>
// The hub's cookie counts for fetch() only with the XSRF token (JupyterHub >= 4.1).
const xsrf = "{{xsrf}}";
function cell(text){const td=document.createElement("td");td.textContent=text;return td;}
let names={};  // the LMS's name of each learner who came from it, by hub name
function named(learner){return names[learner]?`${learner} · ${names[learner]}`:learner;}
function options(select, keys){
  for(const k of keys){const label=named(k.slice(k.indexOf("/")+1));
    let o=[...select.options].find(o=>o.value===k);
    if(!o){o=document.createElement("option");o.value=k;select.appendChild(o);}
    if(o.textContent!==label)o.textContent=label;}
}
async function post(path, body){
  const r=await fetch(path,{method:"POST",headers:{"Content-Type":"application/json",
    "X-XSRFToken":xsrf},body:JSON.stringify(body)});
  const data=await r.json();return r.ok?data:Promise.reject(data.error||r.statusText);
}
async function refresh(){
  try{
    const r=await fetch("progress.json",{cache:"no-store",headers:{"X-XSRFToken":xsrf}});
    if(!r.ok)return;
    const data=await r.json();const body=document.querySelector("#class tbody");
    names=data.names||{};
    body.replaceChildren(...data.rows.map(row=>{const tr=document.createElement("tr");
      tr.dataset.learner=row[0];row.forEach((v,i)=>tr.appendChild(cell(i?v:named(v))));
      if(row[row.length-1])tr.className="stuck";return tr;}));
    document.getElementById("summary").textContent=
      `${data.rows.length} learners · updated ${new Date().toLocaleTimeString()}`;
    const lines=data.exercises.length?data.exercises:["No learner is on an exercise yet."];
    document.getElementById("exercises").replaceChildren(...lines.map(line=>{
      const li=document.createElement("li");li.textContent=line;return li;}));
    options(document.getElementById("learner"),data.keys);
    options(document.getElementById("to"),data.keys);
    await detail();
  }catch(e){}
}
async function detail(){
  const key=document.getElementById("learner").value,box=document.getElementById("detail");
  if(!key){box.replaceChildren();return;}
  const r=await fetch("learner.json?key="+encodeURIComponent(key),
    {cache:"no-store",headers:{"X-XSRFToken":xsrf}});
  if(!r.ok)return;const d=await r.json();
  const parts=[["h3",d.key],["p",d.where],["p","Checks "+d.checks],
    ...d.reasons.map(x=>["p",x]),["p",d.exercise?`Exercise ${d.exercise}: `+
    (d.passed?"passed":"not passed yet")+(d.mistake?`; last failure: ${d.mistake}`:""):
    "No exercise in this unit."]];
  if(d.last_error)parts.push(["pre",d.last_error]);
  if(d.exercise)parts.push(["pre",d.code]);
  box.replaceChildren(...parts.map(([tag,text])=>{const e=document.createElement(tag);
    e.textContent=text;if(tag==="pre")e.className=text===d.code?"code":"error";return e;}));
}
document.getElementById("learner").onchange=detail;
document.getElementById("send").onclick=()=>post("notice",{to:document.getElementById("to").value,
  text:document.getElementById("text").value}).then(d=>{document.getElementById("text").value="";
  document.getElementById("sent").textContent="Sent.";},e=>{
  document.getElementById("sent").textContent="⚠ "+e;});
document.getElementById("apply").onclick=()=>post("settings",{reveal_after:
  Number(document.getElementById("reveal").value)}).then(d=>{
  document.getElementById("applied").textContent="Applied: "+d.reveal_after;},e=>{
  document.getElementById("applied").textContent="⚠ "+e;});
refresh();setInterval(refresh,500);
</script></body></html>
"""


if __name__ == "__main__":
    main()
