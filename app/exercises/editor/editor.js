// The dashboard's code editor: Ace (monospace, line numbers, highlighting,
// Tab = 4 spaces, undo) with several files in tabs: the exercise's code and
// any text file of the learner's workspace ~/ros2_ws, opened from the Files
// tree. It talks to the dashboard over its own websocket (see
// app/exercises/editor_server.py). Every change is saved a moment after
// typing stops; each save of Python code comes back with pyflakes marks.
// Completion (with the signature of the selected name) and signature help
// come from Jedi on the server; Format runs ruff there.
(function () {
  "use strict";
  const slug = new URLSearchParams(location.search).get("slug") || "";
  const EXERCISE = "";
  const SAVE_DELAY_MS = 400;
  const SIGNATURE_DELAY_MS = 150;
  const statusEl = document.getElementById("status");
  const fileEl = document.getElementById("file");
  const tabsEl = document.getElementById("tabs");
  const treeEl = document.getElementById("tree");
  const filesButton = document.getElementById("files-button");
  const formatButton = document.getElementById("format-button");
  const signatureEl = document.getElementById("signature");

  ace.config.set("basePath", "ace/");
  const langTools = ace.require("ace/ext/language_tools");
  const editor = ace.edit("editor", {
    theme: "ace/theme/chrome",
    tabSize: 4,
    useSoftTabs: true,
    showPrintMargin: false,
    wrap: true, // the side window is narrow: long lines fold, line numbers stay true
    fontFamily: "'DejaVu Sans Mono', 'Liberation Mono', monospace",
    readOnly: true, // until the saved code has arrived
    enableBasicAutocompletion: true,
    enableLiveAutocompletion: true,
    enableSnippets: false,
  });
  // Some monospace fonts draw "_" below the line box Ace measures: give lines room.
  editor.container.style.lineHeight = "1.45";
  editor.renderer.updateFontSize();
  window.classroomEditor = editor; // for tests and the curious

  // -- files and tabs ---------------------------------------------------------

  const MODES = [
    [/\.py$/, "python"], [/\.(xml|launch|urdf|xacro|sdf)$/, "xml"], [/\.ya?ml$/, "yaml"],
    [/\.(sh|bash)$/, "sh"], [/\.(cfg|ini)$/, "ini"], [/\.md$/, "markdown"], [/\.toml$/, "toml"],
    [/\.json$/, "json"], [/\.(c|cc|cpp|cxx|h|hh|hpp)$/, "c_cpp"],
  ];
  function modeFor(id) {
    if (id === EXERCISE) return "ace/mode/python";
    for (const [pattern, mode] of MODES) if (pattern.test(id)) return "ace/mode/" + mode;
    return "ace/mode/text";
  }
  function isPython(id) { return id === EXERCISE || /\.py$/.test(id); }

  const files = new Map(); // id -> state of one open file
  let active = null;
  window.classroomFiles = files; // for tests

  function newFile(id) {
    const session = ace.createEditSession("", modeFor(id));
    session.setUseWrapMode(true);
    const state = {
      id: id,
      label: id === EXERCISE ? (slug ? slug + ".py" : "(no exercise chosen)") : id.split("/").pop(),
      title: id === EXERCISE ? "your code for this exercise" : "~/ros2_ws/" + id,
      session: session,
      loaded: false,
      applying: false,
      timer: null,
      revision: 0, // saves sent
      acked: 0, // saves the server confirmed
      changes: 0, // edits made (a Format answer applies only if none came since)
      status: "",
      offline: false,
    };
    session.on("change", function () { onChange(state); });
    files.set(id, state);
    renderTabs();
    return state;
  }

  function dirty(state) { return state.timer !== null || state.revision > state.acked; }

  function renderTabs() {
    tabsEl.textContent = "";
    for (const state of files.values()) {
      const tab = document.createElement("div");
      tab.className = "tab" + (state === active ? " active" : "");
      const name = document.createElement("button");
      name.type = "button";
      name.setAttribute("role", "tab");
      name.setAttribute("aria-selected", String(state === active));
      name.title = state.title;
      name.innerHTML = "";
      const label = document.createElement("span");
      label.className = "name" + (dirty(state) ? " dirty" : "");
      label.textContent = state.label;
      name.appendChild(label);
      name.onclick = function () { activate(state.id); };
      tab.appendChild(name);
      if (state.id !== EXERCISE) {
        const close = document.createElement("button");
        close.type = "button";
        close.className = "close";
        close.textContent = "×";
        close.setAttribute("aria-label", "Close " + state.id);
        close.title = "Close (it stays saved in your workspace)";
        close.onclick = function () { closeFile(state.id, true); };
        tab.appendChild(close);
      }
      tabsEl.appendChild(tab);
    }
  }

  function activate(id) {
    const state = files.get(id);
    if (!state) return;
    active = state;
    editor.setSession(state.session);
    editor.setReadOnly(!state.loaded);
    fileEl.textContent = state.title;
    fileEl.title = state.title;
    formatButton.disabled = !isPython(id);
    hideSignature();
    renderTabs();
    showStatus(state);
    editor.focus();
  }

  function closeFile(id, tellServer) {
    const state = files.get(id);
    if (!state || id === EXERCISE) return;
    if (dirty(state)) saveNow(state);
    clearTimeout(state.timer);
    files.delete(id);
    if (tellServer) send({ type: "close", file: id });
    if (active === state) activate(files.has(EXERCISE) ? EXERCISE : (files.keys().next().value ?? EXERCISE));
    renderTabs();
  }

  function setStatus(state, text, offline) {
    state.status = text;
    state.offline = Boolean(offline);
    if (state === active) showStatus(state);
  }
  function showStatus(state) {
    statusEl.textContent = state.status;
    statusEl.classList.toggle("offline", state.offline);
  }

  // -- the socket -------------------------------------------------------------

  let socket = null;
  function send(message) {
    if (socket && socket.readyState === WebSocket.OPEN) {
      socket.send(JSON.stringify(message));
      return true;
    }
    return false;
  }

  function saveNow(state) {
    clearTimeout(state.timer);
    state.timer = null;
    state.revision += 1;
    const sent = send({ type: "save", file: state.id, slug: slug, code: state.session.getValue(), rev: state.revision });
    if (sent) setStatus(state, "saving…");
    else setStatus(state, "offline: your changes stay here and are saved when the dashboard is back", true);
    renderTabs();
  }

  function onChange(state) {
    if (state.applying) return;
    state.changes += 1;
    setStatus(state, "editing…");
    const wasClean = state.timer === null;
    clearTimeout(state.timer);
    state.timer = setTimeout(function () { saveNow(state); }, SAVE_DELAY_MS);
    if (wasClean) renderTabs();
  }

  function load(state, code) {
    state.applying = true;
    state.session.setValue(code); // also resets undo: Ctrl+Z never empties the file
    state.applying = false;
    state.loaded = true;
    if (state === active) {
      editor.setReadOnly(false);
      editor.clearSelection();
      editor.gotoLine(1, 0, false);
    }
  }

  function onMessage(event) {
    const message = JSON.parse(event.data);
    const id = message.file || EXERCISE;
    if (message.type === "load") {
      if (id === EXERCISE && !slug) return;
      let state = files.get(id);
      if (!state) {
        if (message.initial === undefined) return; // a file this window closed meanwhile
        state = newFile(id);
      }
      if (!state.loaded) {
        load(state, message.code);
        setStatus(state, message.note || "saved");
      } else if (dirty(state)) {
        // Edits the server has not seen yet win: they are saved now (a reconnect), or soon.
        if (message.initial) saveNow(state);
      } else if (state.session.getValue() !== message.code) {
        load(state, message.code);
        setStatus(state, message.note || "saved");
      }
      if (message.focus || active === null || (id === EXERCISE && active.id === EXERCISE)) activate(id);
      else if (state === active) editor.setReadOnly(false);
    } else if (message.type === "saved") {
      const state = files.get(id);
      if (!state) return;
      state.acked = Math.max(state.acked, message.rev);
      if (message.rev === state.revision && state.timer === null) {
        setStatus(state, state.formatted === message.rev ? "formatted and saved ✓" : "saved ✓");
      }
      renderTabs();
    } else if (message.type === "problems") {
      const state = files.get(id);
      if (state) state.session.setAnnotations(message.items);
    } else if (message.type === "flush") {
      let saving = false;
      for (const state of files.values()) {
        if (dirty(state)) {
          saveNow(state);
          saving = saving || state.id === EXERCISE;
        }
      }
      if (!saving) send({ type: "flushed" });
    } else if (message.type === "error") {
      const state = files.get(id) || active;
      if (message.file && !files.has(id)) {
        if (active) setStatus(active, message.text, true);
        return;
      }
      if (state) setStatus(state, message.text, true);
    } else if (message.type === "closed") {
      closeFile(id, false);
      if (message.note && active) setStatus(active, message.note);
    } else if (message.type === "tree") {
      showTree(message);
    } else if (message.type === "formatted") {
      onFormatted(message);
    } else if (message.type === "assist") {
      assistNote = message.completion ? "" : message.note;
      if (assistNote && active) setStatus(active, assistNote);
    } else if (message.type in waiting) {
      const resolve = waiting[message.type].get(message.id);
      if (resolve) {
        waiting[message.type].delete(message.id);
        resolve(message);
      }
    }
  }

  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const base = location.pathname.replace(/[^/]*$/, "");
    socket = new WebSocket(scheme + "://" + location.host + base + "ws?slug=" + encodeURIComponent(slug));
    socket.onopen = function () {
      for (const state of files.values()) {
        if (state.id !== EXERCISE) send({ type: "open", file: state.id });
        setStatus(state, "connected");
      }
      if (treeShown()) refreshTree();
    };
    socket.onmessage = onMessage;
    socket.onclose = function () {
      for (const kind in waiting) { // questions that will get no answer now
        for (const resolve of waiting[kind].values()) resolve({ items: [] });
        waiting[kind].clear();
      }
      for (const state of files.values()) setStatus(state, "offline: reconnecting… (your changes stay here)", true);
      setTimeout(connect, 1000);
    };
  }

  // -- the workspace tree -----------------------------------------------------

  const expanded = new Set(["", "src"]);
  const listings = new Map(); // folder -> entries
  function treeShown() { return !treeEl.hidden; }

  filesButton.onclick = function () {
    treeEl.hidden = !treeEl.hidden;
    filesButton.setAttribute("aria-expanded", String(treeShown()));
    editor.resize();
    if (treeShown()) refreshTree();
  };

  function refreshTree() {
    for (const folder of expanded) send({ type: "tree", folder: folder });
  }

  function showTree(message) {
    listings.set(message.folder, message);
    drawTree();
  }

  function drawTree() {
    treeEl.textContent = "";
    const hint = document.createElement("p");
    hint.textContent = "~/ros2_ws — click a file to open it";
    treeEl.appendChild(hint);
    const root = listings.get("");
    if (!root) return;
    if (root.note && !root.entries.length) {
      const note = document.createElement("p");
      note.textContent = root.note;
      treeEl.appendChild(note);
    }
    treeEl.appendChild(drawFolder("", 0));
  }

  function drawFolder(folder, depth) {
    const list = document.createElement("ul");
    list.setAttribute("role", depth ? "group" : "tree");
    const listing = listings.get(folder);
    for (const entry of (listing ? listing.entries : [])) {
      const item = document.createElement("li");
      item.setAttribute("role", "treeitem");
      const row = document.createElement("span");
      row.style.paddingLeft = (6 + depth * 12) + "px";
      const name = entry.path ? entry.path.split("/").pop() : "";
      item.setAttribute("aria-label", entry.folder ? name + "/" : (name || entry.note));
      if (!entry.path) {
        row.className = "note";
        row.textContent = entry.note;
      } else if (entry.folder) {
        const open = expanded.has(entry.path);
        item.setAttribute("aria-expanded", String(open));
        row.textContent = (open ? "▾ " : "▸ ") + name + "/";
        if (entry.note) {
          const note = document.createElement("span");
          note.className = "note";
          note.textContent = " (" + entry.note + ")";
          row.appendChild(note);
        }
        row.onclick = function () {
          if (expanded.has(entry.path)) expanded.delete(entry.path);
          else {
            expanded.add(entry.path);
            send({ type: "tree", folder: entry.path });
          }
          drawTree();
        };
      } else {
        row.textContent = "  " + name;
        row.title = "Open ~/ros2_ws/" + entry.path;
        row.onclick = function () { openFile(entry.path); };
      }
      item.appendChild(row);
      if (entry.folder && expanded.has(entry.path) && listings.has(entry.path)) {
        item.appendChild(drawFolder(entry.path, depth + 1));
      }
      list.appendChild(item);
    }
    return list;
  }

  function openFile(path) {
    if (files.has(path)) activate(path);
    else send({ type: "open", file: path });
    if (window.matchMedia("(max-width: 699px)").matches) { // the tree covers the code: close it
      treeEl.hidden = true;
      filesButton.setAttribute("aria-expanded", "false");
    }
  }
  window.classroomOpen = openFile; // for tests

  // -- completion, signature help, format -------------------------------------

  let assistNote = "";
  let nextRequest = 1;
  let lastCompletion = 0;
  let waitingCompletions = [];
  const waiting = { complete: new Map(), doc: new Map(), signatures: new Map() };
  function ask(kind, fields) {
    return new Promise(function (resolve) {
      const id = nextRequest++;
      waiting[kind].set(id, resolve);
      if (!send(Object.assign({ type: kind, id: id }, fields))) {
        waiting[kind].delete(id);
        resolve({ items: [] });
      }
    });
  }

  function escapeHtml(text) {
    return String(text).replace(/[&<>"]/g, function (c) {
      return { "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c];
    });
  }

  const serverCompleter = {
    id: "jedi",
    triggerCharacters: ["."],
    getCompletions: function (ed, session, pos, prefix, callback) {
      const state = active;
      if (!state || !isPython(state.id) || assistNote) return callback(null, []);
      // Ace may ask again on every key while an answer is on its way. Only the newest
      // question's answer counts, and it answers every question still waiting: an
      // empty answer to an old one would close the list before the right one arrives.
      const asked = ++lastCompletion;
      waitingCompletions.push(callback);
      const where = { file: state.id, code: session.getValue(), row: pos.row, column: pos.column };
      ask("complete", where).then(function (answer) {
        if (asked !== lastCompletion) return;
        const callbacks = waitingCompletions;
        waitingCompletions = [];
        // Typed on past the name meanwhile (a space, a bracket): the answer is stale.
        const now = editor.getCursorPosition();
        const typed = now.row === pos.row ? session.getLine(now.row).slice(pos.column, now.column) : null;
        const stale = state !== active || typed === null || !/^[A-Za-z0-9_]*$/.test(typed);
        const items = stale ? [] : (answer.items || []).map(function (item, i) {
          return {
            caption: item.name,
            value: item.name,
            meta: item.type,
            score: 100000 - i,
            completerId: "jedi",
            where: where,
          };
        });
        for (const done of callbacks) done(null, items);
      });
    },
    getDocTooltip: function (item) {
      if (item.docHTML !== undefined || !item.where) return item;
      item.docHTML = "<div class='ace_doc'><i>" + escapeHtml(item.value) + "…</i></div>";
      ask("doc", Object.assign({ name: item.value }, item.where)).then(function (answer) {
        const doc = answer.items || {};
        const head = (doc.signatures && doc.signatures.length) ? doc.signatures.join("\n") : (doc.name || item.value);
        item.docHTML = "<div class='ace_doc' style='white-space:pre-wrap;max-width:420px'><b>" + escapeHtml(head) +
          "</b>" + (doc.doc ? "\n\n" + escapeHtml(doc.doc) : "") + "</div>";
        if (editor.completer && editor.completer.popup && editor.completer.popup.isOpen) {
          editor.completer.updateDocTooltip();
        }
      });
      return item;
    },
  };
  editor.completers = [serverCompleter, langTools.keyWordCompleter];

  // Signature help: inside a call's parentheses, the signature with the current parameter bold.
  let signatureTimer = null;
  let signatureAsked = 0;
  function hideSignature() {
    signatureEl.hidden = true;
    signatureAsked += 1; // answers on their way are stale now
  }
  function askSignature() {
    clearTimeout(signatureTimer);
    signatureTimer = setTimeout(function () {
      const state = active;
      if (!state || !isPython(state.id) || assistNote) return hideSignature();
      const pos = editor.getCursorPosition();
      const asked = ++signatureAsked;
      ask("signatures", { file: state.id, code: state.session.getValue(), row: pos.row, column: pos.column })
        .then(function (answer) {
          if (asked !== signatureAsked || state !== active) return;
          const sig = (answer.items || [])[0];
          if (!sig) { signatureEl.hidden = true; return; }
          const params = sig.params.map(function (p, i) {
            return i === sig.index ? "<b>" + escapeHtml(p) + "</b>" : escapeHtml(p);
          });
          signatureEl.innerHTML = escapeHtml(sig.name) + "(" + params.join(", ") + ")";
          const at = editor.renderer.textToScreenCoordinates(pos.row, pos.column);
          signatureEl.hidden = false;
          const height = signatureEl.offsetHeight;
          signatureEl.style.left = Math.max(4, Math.min(at.pageX, window.innerWidth - signatureEl.offsetWidth - 4)) + "px";
          signatureEl.style.top = Math.max(4, at.pageY - height - 4) + "px";
        });
    }, SIGNATURE_DELAY_MS);
  }
  editor.commands.on("afterExec", function (e) {
    if (e.command.name === "insertstring" && (e.args === "(" || e.args === ",")) askSignature();
    else if (e.command.name === "insertstring" && e.args === ")") hideSignature();
  });
  editor.selection.on("changeCursor", function () { if (!signatureEl.hidden) askSignature(); });
  editor.commands.addCommand({
    name: "hideSignature", bindKey: { win: "Esc", mac: "Esc" },
    exec: function () { hideSignature(); return false; },
    passEvent: true,
  });
  editor.on("blur", function () { setTimeout(function () { if (!editor.isFocused()) hideSignature(); }, 200); });

  formatButton.onclick = function () {
    const state = active;
    if (!state || !isPython(state.id)) return;
    setStatus(state, "formatting…");
    send({ type: "format", file: state.id, code: state.session.getValue(), rev: state.changes });
  };

  function onFormatted(message) {
    const state = files.get(message.file || EXERCISE);
    if (!state) return;
    if (message.error) { setStatus(state, message.error, true); return; }
    if (message.rev !== state.changes) { setStatus(state, "not formatted: you typed meanwhile (press Format again)"); return; }
    const session = state.session;
    if (session.getValue() === message.code) { setStatus(state, "already formatted ✓"); return; }
    const cursor = state === active ? editor.getCursorPosition() : null;
    const last = session.doc.getLength() - 1;
    const Range = ace.require("ace/range").Range;
    session.replace(new Range(0, 0, last, session.getLine(last).length), message.code); // Ctrl+Z undoes it
    if (cursor) editor.moveCursorTo(Math.min(cursor.row, session.doc.getLength() - 1), cursor.column);
    saveNow(state);
    state.formatted = state.revision;
    setStatus(state, "formatted, saving…");
  }

  // -- start ------------------------------------------------------------------

  if (slug) activate(newFile(EXERCISE).id);
  connect();
})();
