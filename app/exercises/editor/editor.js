// The Exercise tab's code editor: Ace (monospace, line numbers, Python
// highlighting, Tab = 4 spaces, undo) talking to the dashboard over its own
// websocket. Every change is saved a moment after typing stops; the server
// answers "saved", pushes code on "Reset to starter", pushes lint problems
// as gutter marks, and asks for an immediate save before Run and Check.
(function () {
  "use strict";
  const slug = new URLSearchParams(location.search).get("slug") || "";
  const SAVE_DELAY_MS = 400;
  const statusEl = document.getElementById("status");
  document.getElementById("file").textContent = slug ? slug + ".py" : "(no exercise chosen)";

  ace.config.set("basePath", "ace/");
  const editor = ace.edit("editor", {
    mode: "ace/mode/python",
    theme: "ace/theme/chrome",
    tabSize: 4,
    useSoftTabs: true,
    showPrintMargin: false,
    wrap: true, // the side window is narrow: long lines fold, line numbers stay true
    fontFamily: "'DejaVu Sans Mono', 'Liberation Mono', monospace",
    readOnly: true, // until the saved code has arrived
  });
  // Some monospace fonts draw "_" below the line box Ace measures: give lines room.
  editor.container.style.lineHeight = "1.45";
  editor.renderer.updateFontSize();
  window.classroomEditor = editor; // for tests and the curious

  let socket = null;
  let applyingServerCode = false;
  let saveTimer = null;
  let revision = 0;
  let lastAcked = 0;

  function setStatus(text, offline) {
    statusEl.textContent = text;
    statusEl.classList.toggle("offline", Boolean(offline));
  }

  function send(message) {
    if (socket && socket.readyState === WebSocket.OPEN) {
      socket.send(JSON.stringify(message));
      return true;
    }
    return false;
  }

  function saveNow() {
    clearTimeout(saveTimer);
    saveTimer = null;
    revision += 1;
    if (send({ type: "save", slug: slug, code: editor.getValue(), rev: revision })) {
      setStatus("saving…");
    } else {
      setStatus("offline: your changes stay here and are saved when the dashboard is back", true);
    }
  }

  editor.session.on("change", function () {
    if (applyingServerCode) return;
    setStatus("editing…");
    clearTimeout(saveTimer);
    saveTimer = setTimeout(saveNow, SAVE_DELAY_MS);
  });

  function load(code, keepHistory) {
    applyingServerCode = true;
    editor.session.setValue(code); // also resets undo: Ctrl+Z never empties the file
    applyingServerCode = false;
    editor.setReadOnly(false);
    if (!keepHistory) editor.clearSelection();
    editor.gotoLine(1, 0, false);
  }

  function onMessage(event) {
    const message = JSON.parse(event.data);
    if (message.type === "load") {
      const unsaved = saveTimer !== null || revision > lastAcked;
      if (message.initial && unsaved && !editor.getReadOnly()) {
        saveNow(); // reconnected with edits the server has not seen: ours win
      } else {
        load(message.code);
        setStatus(message.note || "saved");
      }
    } else if (message.type === "saved") {
      lastAcked = Math.max(lastAcked, message.rev);
      if (message.rev === revision && saveTimer === null) setStatus("saved ✓");
    } else if (message.type === "problems") {
      editor.session.setAnnotations(message.items);
    } else if (message.type === "flush") {
      if (saveTimer !== null || revision > lastAcked) saveNow();
      else send({ type: "flushed" });
    } else if (message.type === "error") {
      setStatus(message.text, true);
    }
  }

  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const base = location.pathname.replace(/[^/]*$/, "");
    socket = new WebSocket(scheme + "://" + location.host + base + "ws?slug=" + encodeURIComponent(slug));
    socket.onopen = function () { setStatus("connected"); };
    socket.onmessage = onMessage;
    socket.onclose = function () {
      setStatus("offline: reconnecting… (your changes stay here)", true);
      setTimeout(connect, 1000);
    };
  }
  connect();
})();
