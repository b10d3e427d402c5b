// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * stop.js - the Stop button of an experiment panel (experiment.js,
 * loop.js). It is enabled while the panel follows a running experiment; a
 * click ends the panel's polling and sends DELETE /api/v1/experiments/ID.
 * The experiment's fresh session, which the page asks the daemon to keep
 * for its plots (keep_session), stays when the plots follow it, its
 * controls the user's again; else the page deletes it too. A refused stop
 * is a message: after a 404 (the experiment is gone already) the panel is
 * ready for a new run, after any other it follows the experiment again.
 */

import * as api from './api.js';
import { app, $, message, report, setOnline, poll } from './ui.js';
import { detach, refreshSessionList } from './session.js';

/* The follower of the panel whose Stop button is sel and progress box
 * box: follow(j, get, onUpdate) polls experiment j ({id, sessionId}) as
 * ui.js poll does, Stop enabled meanwhile, and returns the experiment's
 * last answer once it is over, or null once Stop has ended it. */
export function stopButton(sel, box) {
	const button = $(sel);
	let running = null; /* the AbortController of the poll under way */
	button.disabled = true;
	button.addEventListener('click', () => {
		if (!running) return;
		button.disabled = true;
		running.abort();
	});
	return async function follow(j, get, onUpdate) {
		for (;;) {
			running = new AbortController();
			button.disabled = false;
			let end;
			try {
				end = await poll(get, j.id, onUpdate, running.signal);
			} finally {
				running = null;
				button.disabled = true;
			}
			if (end) return end;
			if (await stopExperiment(j)) {
				$(box).querySelector('.ptext').textContent = 'stopped';
				return null;
			}
		}
	};
}

/* DELETE the experiment, then see to its session: kept while the plots
 * follow it (and it still exists), else deleted. True once the experiment
 * is gone. */
async function stopExperiment({ id, sessionId }) {
	try {
		await api.deleteExperiment(id);
		setOnline(true);
	} catch (err) {
		report(err, 'Stop');
		return err instanceof api.ApiError && err.status === 404;
	}
	const removed = `Experiment ${id} stopped; its session was removed.`;
	if (!sessionId) {
		message('warn', `Experiment ${id} stopped.`);
	} else if (app.id === sessionId) {
		const s = await api.getSession(sessionId).catch(err => err);
		if (s instanceof api.ApiError && s.status === 404) {
			detach();
			message('warn', removed);
		} else {
			const how = s instanceof Error || !s.state || s.state === 'running' ? 'keeps running' : `stays (${s.state})`;
			message('warn', `Experiment ${id} stopped; session ${sessionId} ${how}.`);
		}
	} else {
		try {
			await api.deleteSession(sessionId);
			message('warn', removed);
		} catch (err) {
			if (err instanceof api.ApiError && err.status === 404) message('warn', removed);
			else { message('warn', `Experiment ${id} stopped.`); report(err, `Delete session ${sessionId}`); }
		}
	}
	refreshSessionList();
	return true;
}
