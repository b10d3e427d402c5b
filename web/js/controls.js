// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * controls.js - the live-control card of the attached session: pause,
 * resume (for a finished session: run on) and delete; the beta slider, its number field and the quick
 * buttons (with the optional slew rate); the rotation flip; the drive row
 * (motor on/off, omega_ss, pace). Each change is one PATCH (session.js).
 */

import { app, $, $$, numberOf } from './ui.js';
import { patch, setBeta, removeSession } from './session.js';

export function wireControls() {
	$('#pause').onclick = () => patch({ running: false }, 'Pause');
	/* a finished session runs on without an end (at pace "max" the
	 * daemon sets one 60 s on again) */
	$('#resume').onclick = () => (app.session?.state === 'finished'
		? patch({ until: null }, 'Run on') : patch({ running: true }, 'Resume'));
	$('#delete').onclick = removeSession;
	$('#flip').onclick = () => {
		const now = app.session?.rotation ?? 'cw';
		patch({ rotation: now === 'cw' ? 'ccw' : 'cw' }, 'Rotation change');
	};
	$('#motor').onclick = () => {
		const on = app.session?.driveOn !== false;
		patch({ motor_on: !on }, on ? 'Drive off' : 'Drive on');
	};
	$('#omega-ss').addEventListener('change', () => {
		const w = numberOf($('#omega-ss'));
		if (Number.isFinite(w)) patch({ omega_ss: w }, 'ω_ss change');
	});
	$('#pace-live').addEventListener('change', () => {
		const text = $('#pace-live').value.trim();
		const pace = text === 'max' ? 'max' : Number(text);
		patch({ pace }, 'Pace change');
	});
	const slider = $('#beta-slider'), number = $('#beta-number');
	slider.addEventListener('input', () => { app.betaEditing = true; number.value = slider.value; });
	slider.addEventListener('change', async () => {
		await setBeta(Number(slider.value));
		app.betaEditing = false;
	});
	number.addEventListener('change', () => {
		const v = numberOf(number);
		if (Number.isFinite(v)) { slider.value = String(v); setBeta(v); }
	});
	for (const b of $$('.quick')) b.addEventListener('click', () => {
		const v = Number(b.dataset.beta);
		slider.value = String(v); number.value = String(v);
		setBeta(v);
	});
}
